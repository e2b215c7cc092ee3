// collision/src/volumes/bvh_volumes.cpp -- fitting the BVH node volumes to a node's triangles.
// Invariant: every fitted volume contains every corner it was fitted to, by construction: extents
// are exact projections (or the exact farthest distance) enlarged by a slack relative to the
// corners' magnitude that absorbs the rounding of the projections.
#include "volumes/bvh_volumes.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "collision/assert.h"
#include "volumes/covariance.h"
#include "volumes/fit_slack.h"

namespace collision {

namespace {

// Largest |coordinate| plus the largest extent of the set: the magnitude the rounding of any
// projection of these points is relative to.
Real magnitude(const Vec3& lo, const Vec3& hi) {
    return (hi - lo).maxCoeff() + std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
}

Real magnitude(const std::vector<Vec3>& pts) {
    Vec3 lo = pts[0];
    Vec3 hi = pts[0];
    for (const Vec3& p : pts) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    return magnitude(lo, hi);
}

}  // namespace

// Eigenvectors of a covariance matrix as a right-handed orthonormal frame, largest variance first.
// A failed or degenerate solve gives the identity or any perpendicular completion: the fits
// measure extents along whatever axes they get, so containment never depends on this.
Mat3 axesOfCovariance(const Mat3& cov) {
    Eigen::SelfAdjointEigenSolver<Mat3> solver;
    solver.computeDirect(cov);
    Mat3 axes = Mat3::Identity();
    const Vec3 e0 = solver.eigenvectors().col(2);
    const Vec3 e1 = solver.eigenvectors().col(1);
    const Real n0 = e0.norm();
    if (solver.info() == Eigen::Success && std::isfinite(n0) && n0 > Real(0.5)) {
        // Gram-Schmidt so the axes are orthonormal to rounding whatever the solver returned.
        axes.col(0) = e0 / n0;
        Vec3 v1 = e1 - axes.col(0) * axes.col(0).dot(e1);
        const Real n1 = v1.norm();
        if (n1 > Real(0.5)) {
            axes.col(1) = v1 / n1;
        } else {
            // Pick any unit vector perpendicular to col(0).
            const Vec3 any = std::abs(axes(0, 0)) < Real(0.9) ? Vec3::UnitX() : Vec3::UnitY();
            axes.col(1) = axes.col(0).cross(any).normalized();
        }
        axes.col(2) = axes.col(0).cross(axes.col(1));
    }
    return axes;
}

// Principal axes of the triangles (consecutive corner triples), area weighted, about the first
// corner (surfaceCovariance). Columns: largest variance first; right-handed.
Mat3 principalAxes(const std::vector<Vec3>& corners) {
    const Vec3 origin = corners[0];
    return axesOfCovariance(surfaceCovariance(
        origin, corners.size() / 3,
        [&](std::size_t k) {
            return std::array<Vec3, 3>{corners[3 * k], corners[3 * k + 1], corners[3 * k + 2]};
        },
        corners));
}

TriangleMoments triangleMoments(const Vec3& p0, const Vec3& q0, const Vec3& r0,
                                const Vec3& origin) {
    // The same sums as principalAxes, per triangle, so a node's moments are a sum over its
    // triangles (computed once at build instead of once per node level).
    const Vec3 p = p0 - origin;
    const Vec3 q = q0 - origin;
    const Vec3 r = r0 - origin;
    TriangleMoments t;
    t.area = Real(0.5) * (q - p).cross(r - p).norm();
    const Vec3 m = (p + q + r) / Real(3);
    t.first = t.area * m;
    t.second =
        t.area / Real(12) *
        (Real(9) * m * m.transpose() + p * p.transpose() + q * q.transpose() + r * r.transpose());
    return t;
}

bool momentAxes(const TriangleMoments& m, Mat3* axes) {
    if (!(m.area > 0)) return false;
    const Vec3 mu = m.first / m.area;
    *axes = axesOfCovariance(m.second / m.area - mu * mu.transpose());
    return true;
}

bool triangleAxes(const Vec3& p, const Vec3& q, const Vec3& r, Mat3* axes) {
    const std::array<Vec3, 3> edges{q - p, r - q, p - r};
    int longest = 0;
    for (int k = 1; k < 3; ++k) {
        if (edges[static_cast<std::size_t>(k)].squaredNorm() >
            edges[static_cast<std::size_t>(longest)].squaredNorm()) {
            longest = k;
        }
    }
    const Vec3 n = (q - p).cross(r - p);
    const Vec3& e = edges[static_cast<std::size_t>(longest)];
    const Real n_len = n.norm();
    const Real e_len = e.norm();
    // A sliver whose normal is lost in rounding: let the caller use the covariance instead.
    if (!(n_len > Real(16) * kEpsilon * e_len * e_len) || !(e_len > 0)) return false;
    axes->col(0) = e / e_len;
    axes->col(2) = n / n_len;
    axes->col(1) = axes->col(2).cross(axes->col(0));
    return true;
}

BvhTransform makeBvhTransform(const Pose& b_in_a, Real scale_a, Real scale_b) {
    return makeBvhTransform(b_in_a.rotation(), b_in_a.position, scale_a, scale_b);
}

BvhTransform makeBvhTransform(const Mat3& rotation, const Vec3& translation, Real scale_a,
                              Real scale_b) {
    BvhTransform x;
    x.r = rotation;
    x.t = translation;
    x.identity = x.r == Mat3::Identity();
    x.tol = kBvhOverlapSlack * (scale_a + scale_b + x.t.cwiseAbs().maxCoeff());
    for (int k = 0; k < kKdopDirectionCount; ++k) {
        const Vec3 n = kdopDirection(k);
        const auto i = static_cast<std::size_t>(k);
        x.rt_dir[i] = x.r.transpose() * n;
        x.dir_dot_t[i] = n.dot(x.t);
        x.r_dir[i] = x.r * n;
        x.r_dir_dot_t[i] = x.r_dir[i].dot(x.t);
    }
    return x;
}

BoundingSphere BvTraits<BoundingSphere>::fit(const std::vector<Vec3>& corners) {
    CDLAB_ASSERT(!corners.empty(), "fitting a volume to no points");
    return minimalEnclosingSphere(corners);
}

Aabb BvTraits<Aabb>::fit(const std::vector<Vec3>& corners) {
    CDLAB_ASSERT(!corners.empty(), "fitting a volume to no points");
    return finish(bounds(corners.data(), corners.size()));
}

Aabb BvTraits<Aabb>::bounds(const Vec3* points, std::size_t count) {
    Aabb box{points[0], points[0]};
    for (std::size_t k = 0; k < count; ++k) {  // min/max are exact: no slack needed
        box.min = box.min.cwiseMin(points[k]);
        box.max = box.max.cwiseMax(points[k]);
    }
    return box;
}

Obb BvTraits<Obb>::fit(const std::vector<Vec3>& corners) {
    CDLAB_ASSERT(!corners.empty(), "fitting a volume to no points");
    return fitWithAxes(corners, principalAxes(corners));
}

Obb BvTraits<Obb>::fitWithAxes(const std::vector<Vec3>& corners, const Mat3& axes) {
    CDLAB_ASSERT(!corners.empty(), "fitting a volume to no points");
    const Vec3 origin = corners[0];
    Vec3 lo, hi;
    projectionRange(axes, corners, origin, lo, hi);  // corners[0] projects to exactly 0
    Obb box = boxOfRange(axes, origin, lo, hi);
    box.half_extents += Vec3::Constant(kFitSlack * magnitude(corners));
    return box;
}

void BvTraits<Obb>::widen(Obb& box, const Aabb& points_box) {
    box.half_extents += Vec3::Constant(kFitSlack * magnitude(points_box.min, points_box.max));
}

template <int K>
Kdop<K> BvTraits<Kdop<K>>::fit(const std::vector<Vec3>& corners) {
    CDLAB_ASSERT(!corners.empty(), "fitting a volume to no points");
    return finish(bounds(corners.data(), corners.size()));
}

template <int K>
typename BvTraits<Kdop<K>>::Bounds BvTraits<Kdop<K>>::bounds(const Vec3* points,
                                                             std::size_t count) {
    Bounds b;
    b.slabs.min.fill(std::numeric_limits<Real>::infinity());
    b.slabs.max.fill(-std::numeric_limits<Real>::infinity());
    b.lo = points[0];
    b.hi = points[0];
    for (std::size_t k = 0; k < count; ++k) {
        const Vec3& p = points[k];
        for (int i = 0; i < Kdop<K>::kSlabs; ++i) {
            const Real s = kdopDirection(kdopDirectionIndex<K>(i)).dot(p);
            b.slabs.min[i] = std::min(b.slabs.min[i], s);
            b.slabs.max[i] = std::max(b.slabs.max[i], s);
        }
        if constexpr (kNeedsBox) {
            b.lo = b.lo.cwiseMin(p);
            b.hi = b.hi.cwiseMax(p);
        }
    }
    return b;
}

template <int K>
Kdop<K> BvTraits<Kdop<K>>::finish(const Bounds& b) {
    Kdop<K> d = b.slabs;
    if constexpr (Kdop<K>::kSlabs > 3) {
        // The axis slabs are exact coordinates; the diagonal ones are rounded sums of up to three
        // coordinates: widen every slab by a few ulps of 3 x the magnitude.
        const Real slack = Real(3) * kFitSlack * magnitude(b.lo, b.hi);
        for (int i = 3; i < Kdop<K>::kSlabs; ++i) {
            d.min[i] -= slack;
            d.max[i] += slack;
        }
    }
    return d;
}

template struct BvTraits<Kdop<6>>;
template struct BvTraits<Kdop<14>>;
template struct BvTraits<Kdop<18>>;
template struct BvTraits<Kdop<26>>;

namespace {

// The corners as coordinates along `axes` relative to the first corner (`origin`), and their box
// in that frame (which holds the origin).
struct AxesFramePoints {
    Vec3 origin;
    std::vector<Vec3> points;
    Vec3 lo = Vec3::Zero();
    Vec3 hi = Vec3::Zero();
};

AxesFramePoints inAxesFrame(const std::vector<Vec3>& corners, const Mat3& axes) {
    CDLAB_ASSERT(!corners.empty(), "fitting a volume to no points");
    AxesFramePoints out;
    out.origin = corners[0];
    const Vec3& origin = out.origin;
    out.points.reserve(corners.size());
    for (const Vec3& p : corners) {
        out.points.push_back(axes.transpose() * (p - origin));
        out.lo = out.lo.cwiseMin(out.points.back());
        out.hi = out.hi.cwiseMax(out.points.back());
    }
    return out;
}

}  // namespace

Rss BvTraits<Rss>::fit(const std::vector<Vec3>& corners) {
    CDLAB_ASSERT(!corners.empty(), "fitting a volume to no points");
    return fitWithAxes(corners, principalAxes(corners));
}

Rss BvTraits<Rss>::fitWithAxes(const std::vector<Vec3>& corners, const Mat3& axes) {
    // Larsen et al. 2000 §4: the rectangle spans the two largest principal axes; the radius is
    // half the thickness along the third. The rectangle is then shrunk as far as every point's
    // own slack sqrt(r^2 - dz^2) allows on each axis, and the radius re-measured exactly, so
    // points near the rounded corners are covered by construction.
    const AxesFramePoints frame = inAxesFrame(corners, axes);
    const Vec3& origin = frame.origin;
    const std::vector<Vec3>& local = frame.points;
    const Vec3& lo = frame.lo;
    const Vec3& hi = frame.hi;
    const Real cz = (lo.z() + hi.z()) * Real(0.5);
    const Real r = (hi.z() - lo.z()) * Real(0.5);
    Real x0 = std::numeric_limits<Real>::infinity();
    Real x1 = -x0;
    Real y0 = x0;
    Real y1 = -x0;
    for (const Vec3& q : local) {
        const Real dz = q.z() - cz;
        const Real s = std::sqrt(std::max(Real(0), r * r - dz * dz));
        x0 = std::min(x0, q.x() + s);
        x1 = std::max(x1, q.x() - s);
        y0 = std::min(y0, q.y() + s);
        y1 = std::max(y1, q.y() - s);
    }
    if (x0 > x1) x0 = x1 = (x0 + x1) * Real(0.5);
    if (y0 > y1) y0 = y1 = (y0 + y1) * Real(0.5);
    Real radius = 0;
    for (const Vec3& q : local) {
        const Real dx = std::max({Real(0), x0 - q.x(), q.x() - x1});
        const Real dy = std::max({Real(0), y0 - q.y(), q.y() - y1});
        const Real dz = q.z() - cz;
        radius = std::max(radius, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
    Rss s;
    s.axes = axes;
    s.center = origin + axes * Vec3((x0 + x1) * Real(0.5), (y0 + y1) * Real(0.5), cz);
    s.half_lengths = {(x1 - x0) * Real(0.5), (y1 - y0) * Real(0.5)};
    s.radius = radius + kFitSlack * magnitude(corners);
    return s;
}

Lss BvTraits<Lss>::fit(const std::vector<Vec3>& corners) {
    CDLAB_ASSERT(!corners.empty(), "fitting a volume to no points");
    return fitWithAxes(corners, principalAxes(corners));
}

Lss BvTraits<Lss>::fitWithAxes(const std::vector<Vec3>& corners, const Mat3& axes) {
    // Larsen et al. 2000 §4 for the line: the segment runs along the largest principal axis
    // through the centre of the points' box across it; the radius is the largest distance across
    // the axis. The segment is then shrunk as far as every point's own slack sqrt(r^2 - d^2)
    // allows (as for the RSS), and the radius re-measured as the exact largest distance of a
    // point from the final segment, so the volume contains every corner by construction
    // (conservative whatever the axis; the axis only decides how tight it is).
    const AxesFramePoints frame = inAxesFrame(corners, axes);
    const Vec3& origin = frame.origin;
    const std::vector<Vec3>& local = frame.points;
    const Vec3& lo = frame.lo;
    const Vec3& hi = frame.hi;
    const Real cy = (lo.y() + hi.y()) * Real(0.5);
    const Real cz = (lo.z() + hi.z()) * Real(0.5);
    auto across2 = [&](const Vec3& q) {
        return (q.y() - cy) * (q.y() - cy) + (q.z() - cz) * (q.z() - cz);
    };
    Real r2 = 0;
    for (const Vec3& q : local) r2 = std::max(r2, across2(q));
    Real x0 = std::numeric_limits<Real>::infinity();
    Real x1 = -x0;
    for (const Vec3& q : local) {
        const Real s = std::sqrt(std::max(Real(0), r2 - across2(q)));
        x0 = std::min(x0, q.x() + s);
        x1 = std::max(x1, q.x() - s);
    }
    if (x0 > x1) x0 = x1 = (x0 + x1) * Real(0.5);
    Real radius = 0;
    for (const Vec3& q : local) {
        const Real dx = std::max({Real(0), x0 - q.x(), q.x() - x1});
        radius = std::max(radius, std::sqrt(dx * dx + across2(q)));
    }
    Lss s;
    s.axis = axes.col(0);
    s.center = origin + axes * Vec3((x0 + x1) * Real(0.5), cy, cz);
    s.half_length = (x1 - x0) * Real(0.5);
    s.radius = radius + kFitSlack * magnitude(corners);
    return s;
}

}  // namespace collision
