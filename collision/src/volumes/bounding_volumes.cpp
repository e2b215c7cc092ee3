// collision/src/volumes/bounding_volumes.cpp -- fitting of spheres and AABBs (the OBB fits are in
// obb_fit.cpp) and the overlap tests of spheres, AABBs and OBBs. Every fitted volume contains its
// shape: analytically for the primitives, and for point sets after a final relative enlargement
// that absorbs the rounding of the fit (conservative).
#include "collision/volumes/bounding_volumes.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>

#include "collision/assert.h"
#include "collision/geometry/shape.h"
#include "collision/narrowphase/narrow_phase.h"
#include "volumes/box_sat.h"
#include "volumes/fit_slack.h"

namespace collision {

namespace {

struct Ball {
    Vec3 c = Vec3::Zero();
    Real r2 = -1;  // squared radius; negative = empty
};

bool inside(const Ball& b, const Vec3& p, Real slack2) {
    return (p - b.c).squaredNorm() <= b.r2 + slack2;
}

Ball ballFrom1(const Vec3& a) { return Ball{a, 0}; }

Ball ballFrom2(const Vec3& a, const Vec3& b) {
    const Vec3 c = (a + b) * Real(0.5);
    return Ball{c, (a - c).squaredNorm()};
}

// Circumscribed ball of a triangle (RTCD 4.3.5 closed form). Degenerate (collinear) triangles
// fall back to the ball of the farthest pair, which contains the third point.
Ball ballFrom3(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 ab = b - a;
    const Vec3 ac = c - a;
    const Vec3 n = ab.cross(ac);
    const Real denom = Real(2) * n.squaredNorm();
    const Real scale2 = std::max({ab.squaredNorm(), ac.squaredNorm(), (c - b).squaredNorm()});
    if (denom <= kEpsilon * scale2 * scale2) {
        Ball best = ballFrom2(a, b);
        for (const Ball& cand : {ballFrom2(a, c), ballFrom2(b, c)}) {
            if (cand.r2 > best.r2) best = cand;
        }
        return best;
    }
    const Vec3 offset = (ac.squaredNorm() * n.cross(ab) + ab.squaredNorm() * ac.cross(n)) / denom;
    return Ball{a + offset, offset.squaredNorm()};
}

// Circumscribed ball of a tetrahedron; coplanar sets fall back to the smallest of the four
// face balls that contains all four points.
Ball ballFrom4(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    const Vec3 ab = b - a;
    const Vec3 ac = c - a;
    const Vec3 ad = d - a;
    const Real det = ab.dot(ac.cross(ad));
    const Real scale = std::max({ab.norm(), ac.norm(), ad.norm()});
    if (std::abs(det) <= kEpsilon * scale * scale * scale) {
        const Vec3 pts[4] = {a, b, c, d};
        Ball best;
        for (int skip = 0; skip < 4; ++skip) {
            Vec3 q[3];
            int k = 0;
            for (int i = 0; i < 4; ++i) {
                if (i != skip) q[k++] = pts[i];
            }
            const Ball cand = ballFrom3(q[0], q[1], q[2]);
            const Real slack2 = kFitSlack * cand.r2 + kEpsilon;
            if (inside(cand, pts[skip], slack2) && (best.r2 < 0 || cand.r2 < best.r2)) best = cand;
        }
        if (best.r2 >= 0) return best;
        return ballFrom2(a, b);  // unreachable for finite input; keeps the result defined
    }
    // Solve 2 [ab ac ad]^T x = [|ab|^2 |ac|^2 |ad|^2]^T by Cramer's rule (RTCD 4.3.5).
    const Vec3 x = (ab.squaredNorm() * ac.cross(ad) + ac.squaredNorm() * ad.cross(ab) +
                    ad.squaredNorm() * ab.cross(ac)) /
                   (Real(2) * det);
    return Ball{a + x, x.squaredNorm()};
}

// splitmix64: a fixed permutation for Welzl's expected-linear bound, identical on every platform
// (std::shuffle's algorithm is implementation-defined).
std::uint64_t splitmix(std::uint64_t& state) {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

}  // namespace

BoundingSphere minimalEnclosingSphere(const std::vector<Vec3>& input) {
    if (input.empty()) return BoundingSphere{};
    std::vector<Vec3> p = input;
    std::uint64_t seed = 0x5EED;
    for (std::size_t i = p.size(); i > 1; --i) {
        std::swap(p[i - 1], p[splitmix(seed) % i]);
    }
    Real extent = 0;
    for (const Vec3& q : p) extent = std::max(extent, (q - p[0]).norm());
    const Real slack2 = (kFitSlack * extent) * (kFitSlack * extent);

    // Welzl 1991 in its iterative form (Gärtner's nested loops): each loop fixes one more
    // boundary point; with a random order the expected cost is linear.
    Ball ball = ballFrom1(p[0]);
    for (std::size_t i = 1; i < p.size(); ++i) {
        if (inside(ball, p[i], slack2)) continue;
        ball = ballFrom1(p[i]);
        for (std::size_t j = 0; j < i; ++j) {
            if (inside(ball, p[j], slack2)) continue;
            ball = ballFrom2(p[i], p[j]);
            for (std::size_t k = 0; k < j; ++k) {
                if (inside(ball, p[k], slack2)) continue;
                ball = ballFrom3(p[i], p[j], p[k]);
                for (std::size_t l = 0; l < k; ++l) {
                    if (inside(ball, p[l], slack2)) continue;
                    ball = ballFrom4(p[i], p[j], p[k], p[l]);
                }
            }
        }
    }
    // Final pass: the radius is the true maximum distance from the chosen centre, enlarged by the
    // fit slack, so containment holds for every input point by construction.
    Real r2 = 0;
    for (const Vec3& q : input) r2 = std::max(r2, (q - ball.c).squaredNorm());
    const Real r = std::sqrt(r2);
    return BoundingSphere{ball.c, r + kFitSlack * (r + ball.c.cwiseAbs().maxCoeff())};
}

LocalBounds fitLocalBounds(const Shape& shape) {
    LocalBounds b;
    switch (shape.type) {
        case ShapeType::Sphere:
            b.sphere = BoundingSphere{Vec3::Zero(), shape.radius};
            b.obb.half_extents = Vec3::Constant(shape.radius);
            break;
        case ShapeType::Box:
            b.sphere = BoundingSphere{Vec3::Zero(), shape.half_extents.norm()};
            b.obb.half_extents = shape.half_extents;
            break;
        case ShapeType::Capsule:
            b.sphere = BoundingSphere{Vec3::Zero(), shape.half_height + shape.radius};
            b.obb.half_extents =
                Vec3(shape.radius, shape.half_height + shape.radius, shape.radius);
            break;
        case ShapeType::ConvexHull:
        case ShapeType::Mesh:
            // The minimal sphere of a set is that of its hull's vertices.
            b.sphere = minimalEnclosingSphere(shape.hull->vertices);
            b.obb = fitObbTight(*shape.hull);
            break;
    }
    return b;
}

namespace {

// The touching tolerance of the narrow phase, as an absolute margin for a volume of this size:
// broad-phase volumes are enlarged by it so that every pair the narrow phase would call Touching
// is flagged (flagged ⊇ colliding holds on the boundary too).
Real touchMargin(Real size) { return kTouchRelativeTolerance * size; }

}  // namespace

Aabb computeWorldAabb(const Shape& shape, const Pose& pose) {
    const Mat3 r = pose.rotation();
    Vec3 lo = pose.position;
    Vec3 hi = pose.position;
    switch (shape.type) {
        case ShapeType::Sphere:
            lo = pose.position - Vec3::Constant(shape.radius);
            hi = pose.position + Vec3::Constant(shape.radius);
            break;
        case ShapeType::Box: {
            // RTCD 4.2.6: the extent of a rotated box on world axis i is sum_j |R_ij| h_j.
            const Vec3 e = r.cwiseAbs() * shape.half_extents;
            lo = pose.position - e;
            hi = pose.position + e;
            break;
        }
        case ShapeType::Capsule: {
            // Segment endpoints p ± R e_y h, each swept by the radius.
            const Vec3 e = r.col(1).cwiseAbs() * shape.half_height +
                           Vec3::Constant(shape.radius);
            lo = pose.position - e;
            hi = pose.position + e;
            break;
        }
        case ShapeType::ConvexHull:
        case ShapeType::Mesh: {
            lo = Vec3::Constant(std::numeric_limits<Real>::max());
            hi = Vec3::Constant(std::numeric_limits<Real>::lowest());
            for (const Vec3& v : shape.hull->vertices) {
                const Vec3 w = r * v;
                lo = lo.cwiseMin(w);
                hi = hi.cwiseMax(w);
            }
            lo += pose.position;
            hi += pose.position;
            break;
        }
    }
    const Real size = (hi - lo).maxCoeff() + pose.position.cwiseAbs().maxCoeff();
    const Vec3 margin = Vec3::Constant(touchMargin(size));
    return Aabb{lo - margin, hi + margin};
}

BoundingSphere transformSphere(const BoundingSphere& local, const Pose& pose) {
    const Vec3 c = pose.apply(local.center);
    const Real size = local.radius + c.cwiseAbs().maxCoeff();
    return BoundingSphere{c, local.radius + touchMargin(size)};
}

Obb transformObb(const Obb& local, const Pose& pose) {
    Obb o;
    o.center = pose.apply(local.center);
    o.axes = pose.rotation() * local.axes;
    const Real size = local.half_extents.maxCoeff() + o.center.cwiseAbs().maxCoeff();
    o.half_extents = local.half_extents + Vec3::Constant(touchMargin(size));
    return o;
}

bool Obb::overlaps(const Obb& o) const {
    // Gottschalk, Lin, Manocha 1996 §4 / RTCD 4.4.1: 15 candidate axes, in A's frame, with a
    // rounding slack relative to the boxes' size and distance.
    const Vec3& a = half_extents;
    const Vec3& b = o.half_extents;
    const Mat3 rot = axes.transpose() * o.axes;  // B's axes in A's frame
    const Vec3 t = axes.transpose() * (o.center - center);
    const Real scale = std::max(a.maxCoeff(), b.maxCoeff());
    const Real tol = Real(16) * kEpsilon * (scale + t.cwiseAbs().maxCoeff());
    return testSat15<false>(a, rot, t, b, tol, 0);
}

void Obb::corners(Vec3 out[8]) const {
    for (int k = 0; k < 8; ++k) {
        const Vec3 s((k & 1) ? 1 : -1, (k & 2) ? 1 : -1, (k & 4) ? 1 : -1);
        out[k] = center + axes * s.cwiseProduct(half_extents);
    }
}

}  // namespace collision
