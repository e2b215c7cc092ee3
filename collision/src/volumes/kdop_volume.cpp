// collision/volumes/kdop_volume.cpp -- see kdop_volume.h.
// The polytope is kept as a list of convex faces, each a vertex loop; every clip keeps the part
// of each face inside the half-space and closes the cut with the cap polygon through the new
// points, so after the last slab the faces are exactly the boundary of the slabs' intersection
// (Klosowski et al. 1998 §3; RTCD 4.6 and 8.3.4).
#include "collision/volumes/kdop_volume.h"

#include <algorithm>
#include <cmath>

#include "collision/assert.h"
#include "collision/geometry/shape.h"

namespace collision {

namespace {

using Face = std::vector<Vec3>;

/// The 13 directions: axes, cube diagonals, face diagonals (the mesh BVH's order).
constexpr int kDirections[13][3] = {{1, 0, 0},  {0, 1, 0},  {0, 0, 1}, {1, 1, 1}, {1, 1, -1},
                                    {1, -1, 1}, {-1, 1, 1}, {1, 1, 0}, {1, 0, 1}, {0, 1, 1},
                                    {1, -1, 0}, {1, 0, -1}, {0, 1, -1}};

/// Index of the first point within `tol` (max-norm) of p in `points`, appending p if none.
int weld(std::vector<Vec3>& points, const Vec3& p, Real tol) {
    for (std::size_t i = 0; i < points.size(); ++i) {
        if ((points[i] - p).cwiseAbs().maxCoeff() <= tol) return int(i);
    }
    points.push_back(p);
    return int(points.size()) - 1;
}

/// The distinct points of `cap` (all on the plane with normal n) in angular order around their
/// centroid, so they form the convex cap polygon.
Face orderCap(const std::vector<Vec3>& cap, const Vec3& n, Real tol) {
    Face points;
    for (const Vec3& p : cap) weld(points, p, tol);
    if (points.size() < 3) return points;
    Vec3 c = Vec3::Zero();
    for (const Vec3& p : points) c += p;
    c /= Real(points.size());
    const Vec3 axis = std::abs(n.x()) < std::abs(n.y()) ? Vec3::UnitX() : Vec3::UnitY();
    const Vec3 u = n.cross(axis);
    const Vec3 v = n.cross(u);
    std::vector<std::pair<Real, int>> order;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const Vec3 r = points[i] - c;
        order.push_back({std::atan2(r.dot(v), r.dot(u)), int(i)});
    }
    std::sort(order.begin(), order.end());
    Face out;
    for (const auto& [angle, i] : order) out.push_back(points[std::size_t(i)]);
    return out;
}

/// Keeps the part of every face with dot(n, p) <= offset (+ tol) and adds the cap face.
std::vector<Face> clip(const std::vector<Face>& faces, const Vec3& n, Real offset, Real tol) {
    std::vector<Face> out;
    std::vector<Vec3> cap;
    for (const Face& face : faces) {
        Face kept;
        for (std::size_t j = 0; j < face.size(); ++j) {
            const Vec3& a = face[j];
            const Vec3& b = face[(j + 1) % face.size()];
            const Real da = n.dot(a) - offset;
            const Real db = n.dot(b) - offset;
            const bool a_in = da <= tol;
            if (a_in) kept.push_back(a);
            if (a_in && da >= -tol) cap.push_back(a);
            if (a_in != (db <= tol)) {
                // One of da, db is > tol and the other <= tol, so da != db.
                const Real t = std::clamp(da / (da - db), Real(0), Real(1));
                const Vec3 p = a + t * (b - a);
                kept.push_back(p);
                cap.push_back(p);
            }
        }
        if (kept.size() >= 2) out.push_back(std::move(kept));
    }
    Face cap_face = orderCap(cap, n, tol);
    if (cap_face.size() >= 2) out.push_back(std::move(cap_face));
    return out;
}

}  // namespace

bool isKdopK(int k) { return k == 6 || k == 14 || k == 18 || k == 26; }

Vec3 kdopSlabDirection(int k, int i) {
    CDLAB_ASSERT(isKdopK(k) && i >= 0 && i < k / 2, "k-DOP slab out of range");
    const int index = (k == 18 && i >= 3) ? i + 4 : i;  // 18: axes then the face diagonals
    const int* d = kDirections[index];
    return Vec3(Real(d[0]), Real(d[1]), Real(d[2]));
}

bool WorldKdop::overlaps(const WorldKdop& o) const {
    CDLAB_ASSERT(k == o.k, "k-DOPs of different k");
    for (int i = 0; i < k / 2; ++i) {
        if (min[std::size_t(i)] > o.max[std::size_t(i)]) return false;
        if (o.min[std::size_t(i)] > max[std::size_t(i)]) return false;
    }
    return true;
}

WorldKdop computeWorldKdop(const Shape& shape, const Pose& pose, int k) {
    CDLAB_ASSERT(isKdopK(k), "k must be 6, 14, 18 or 26");
    WorldKdop out;
    out.k = k;
    const Mat3 r = pose.rotation();
    for (int i = 0; i < k / 2; ++i) {
        // RTCD 4.6.1: each slab is the support of the shape along d and along -d.
        const Vec3 d = kdopSlabDirection(k, i);
        const Vec3 local = r.transpose() * d;
        out.max[std::size_t(i)] = d.dot(pose.apply(supportPoint(shape, local)));
        out.min[std::size_t(i)] = d.dot(pose.apply(supportPoint(shape, -local)));
    }
    return out;
}

Real kdopPolytopeTolerance(const WorldKdop& kdop) {
    Real scale = 0;
    for (int i = 0; i < 3; ++i) {
        scale = std::max(
            {scale, std::abs(kdop.min[std::size_t(i)]), std::abs(kdop.max[std::size_t(i)])});
    }
    return 256 * kEpsilon * scale;
}

KdopPolytope kdopPolytope(const WorldKdop& kdop) {
    CDLAB_ASSERT(isKdopK(kdop.k), "k must be 6, 14, 18 or 26");
    const Real tol = kdopPolytopeTolerance(kdop);
    const Vec3 lo(kdop.min[0], kdop.min[1], kdop.min[2]);
    const Vec3 hi(kdop.max[0], kdop.max[1], kdop.max[2]);
    auto corner = [&](int bits) {
        return Vec3(bits & 1 ? hi.x() : lo.x(), bits & 2 ? hi.y() : lo.y(),
                    bits & 4 ? hi.z() : lo.z());
    };
    // The box of the three axis slabs: corner bit a set = max on axis a. Each face is a loop.
    std::vector<Face> faces;
    for (int axis = 0; axis < 3; ++axis) {
        const int b1 = 1 << ((axis + 1) % 3);
        const int b2 = 1 << ((axis + 2) % 3);
        for (int side = 0; side < 2; ++side) {
            const int base = side ? 1 << axis : 0;
            faces.push_back(
                {corner(base), corner(base | b1), corner(base | b1 | b2), corner(base | b2)});
        }
    }
    for (int i = 3; i < kdop.k / 2; ++i) {
        const Vec3 d = kdopSlabDirection(kdop.k, i);
        faces = clip(faces, d, kdop.max[std::size_t(i)], tol);
        faces = clip(faces, -d, -kdop.min[std::size_t(i)], tol);
    }
    KdopPolytope out;
    for (const Face& face : faces) {
        for (std::size_t j = 0; j < face.size(); ++j) {
            const int a = weld(out.vertices, face[j], tol);
            const int b = weld(out.vertices, face[(j + 1) % face.size()], tol);
            if (a != b) out.edges.push_back({std::min(a, b), std::max(a, b)});
        }
    }
    std::sort(out.edges.begin(), out.edges.end());
    out.edges.erase(std::unique(out.edges.begin(), out.edges.end()), out.edges.end());
    return out;
}

}  // namespace collision
