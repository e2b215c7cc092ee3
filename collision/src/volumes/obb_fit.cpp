// collision/src/volumes/obb_fit.cpp -- the bodies' oriented bounding boxes: the principal-axes fit
// and the tight fit that keeps the smallest of several candidate boxes (fitLocalBounds uses it
// for hulls and meshes; the BVH's node boxes are fitted in bvh_volumes.cpp).
// Invariant: every box returned here is the exact projection range of all the hull's vertices on
// its (orthonormal, right-handed) axes, enlarged by kFitSlack times the hull's size; the
// candidate search only chooses the axes, so it can never cost containment.
// What is exact: for each axis tried, the smallest box with that axis (Freeman & Shapira 1975 in
// the plane normal to it). What is not: the choice of axes. O'Rourke 1985, "Finding minimal
// enclosing boxes", shows a minimum-volume box has two adjacent faces each flush with a hull
// edge, not necessarily a face flush with a hull face; his O(n^3) edge-pair search is not done.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <tuple>
#include <vector>

#include "collision/assert.h"
#include "collision/geometry/shape.h"
#include "collision/volumes/bounding_volumes.h"
#include "volumes/covariance.h"
#include "volumes/fit_slack.h"
#include "volumes/min_area_rectangle.h"

namespace collision {

namespace {

// At most this many hull-face directions are tried (largest planar patches first): the 2-D step
// costs O(F + V + s log s) per direction (s: silhouette vertices), so the cap bounds a hull with
// thousands of faces at about kMaxFaceAxes * O(F + V).
constexpr std::size_t kMaxFaceAxes = 128;
// At most this many hull-edge directions are tried as axes (longest edges first).
constexpr std::size_t kMaxEdgeAxes = 64;
// Alternating refinement rounds on the best box's own axes (each round: its three axes).
constexpr int kMaxRefineRounds = 4;
// Two unit axes are the same candidate when |cos| is within this of 1 (double: 2.2e-12, about
// 2e-6 rad).
constexpr Real kSameAxisCos = Real(1e4) * kEpsilon;
// Adjacent hull triangles belong to one planar patch when their unit normals agree this closely.
constexpr Real kCoplanarCos = Real(1e4) * kEpsilon;
// A vertex is on the silhouette along axis a when its incident faces' normals n have both
// n.a >= -kSilhouetteCos and n.a <= kSilhouetteCos: a superset of the exact silhouette, so no
// extreme vertex of the projection is lost to the rounding of the normals (double: 2.2e-9; in
// float every vertex qualifies, which costs time only).
constexpr Real kSilhouetteCos = Real(1e7) * kEpsilon;

Real magnitude(const Vec3& origin, const Vec3& lo, const Vec3& hi) {
    return (hi - lo).maxCoeff() + origin.cwiseAbs().maxCoeff();
}

// The exact projection box of `v` on `axes` about `origin`, enlarged by the fit slack.
Obb boxOnAxes(const Mat3& axes, const std::vector<Vec3>& v, const Vec3& origin, Real* volume) {
    Vec3 lo, hi;
    projectionRange(axes, v, origin, lo, hi);
    Obb box;
    box.axes = axes;
    box.center = origin + axes * ((lo + hi) * Real(0.5));
    box.half_extents =
        (hi - lo) * Real(0.5) + Vec3::Constant(kFitSlack * magnitude(origin, lo, hi));
    if (volume) *volume = (hi - lo).prod();
    return box;
}

// Principal axes of the hull's area-weighted surface covariance, largest variance first.
Mat3 principalAxes(const ConvexPolytope& hull) {
    const std::vector<Vec3>& v = hull.vertices;
    const Mat3 cov = surfaceCovariance(
        v[0], hull.faces.size(),
        [&](std::size_t k) {
            const auto& f = hull.faces[k];
            return std::array<Vec3, 3>{v[f[0]], v[f[1]], v[f[2]]};
        },
        v);
    Eigen::SelfAdjointEigenSolver<Mat3> solver(cov);
    Mat3 axes = Mat3::Identity();
    if (solver.info() == Eigen::Success && solver.eigenvectors().allFinite()) {
        // Eigen sorts eigenvalues ascending; take the largest-variance axis first.
        axes.col(0) = solver.eigenvectors().col(2).normalized();
        axes.col(1) = solver.eigenvectors().col(1).normalized();
        axes.col(2) = axes.col(0).cross(axes.col(1)).normalized();
        axes.col(1) = axes.col(2).cross(axes.col(0));
    }
    return axes;
}

int findRoot(std::vector<std::int32_t>& parent, std::int32_t f) {
    while (parent[f] != f) {
        parent[f] = parent[parent[f]];
        f = parent[f];
    }
    return f;
}

// Unit normals of the hull's planar patches (edge-adjacent triangles with equal normals merged,
// so a fan-triangulated cap counts as one large face), largest patch area first, ties by lowest
// triangle index. O(F log F).
std::vector<Vec3> patchNormals(const ConvexPolytope& hull, const std::vector<Vec3>& unit) {
    const std::size_t nf = hull.faces.size();
    std::vector<std::tuple<std::int32_t, std::int32_t, std::int32_t>> edges;
    edges.reserve(3 * nf);
    for (std::size_t f = 0; f < nf; ++f) {
        for (int e = 0; e < 3; ++e) {
            const std::int32_t a = hull.faces[f][e];
            const std::int32_t b = hull.faces[f][(e + 1) % 3];
            edges.emplace_back(std::min(a, b), std::max(a, b), static_cast<std::int32_t>(f));
        }
    }
    std::sort(edges.begin(), edges.end());
    std::vector<std::int32_t> parent(nf);
    std::iota(parent.begin(), parent.end(), 0);
    for (std::size_t k = 1; k < edges.size(); ++k) {
        const auto [a0, b0, f0] = edges[k - 1];
        const auto [a1, b1, f1] = edges[k];
        if (a0 != a1 || b0 != b1) continue;
        if (unit[f0].dot(unit[f1]) < Real(1) - kCoplanarCos) continue;
        const int r0 = findRoot(parent, f0);
        const int r1 = findRoot(parent, f1);
        parent[std::max(r0, r1)] = std::min(r0, r1);  // the root is the patch's lowest triangle
    }
    const std::vector<Vec3>& v = hull.vertices;
    std::vector<Vec3> sum(nf, Vec3::Zero());  // twice the area-weighted normal, per root
    for (std::size_t f = 0; f < nf; ++f) {
        const auto& t = hull.faces[f];
        sum[findRoot(parent, static_cast<std::int32_t>(f))] +=
            (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]);
    }
    std::vector<std::int32_t> roots;
    for (std::size_t f = 0; f < nf; ++f) {
        if (parent[f] == static_cast<std::int32_t>(f) && sum[f].norm() > 0) {
            roots.push_back(static_cast<std::int32_t>(f));
        }
    }
    std::stable_sort(roots.begin(), roots.end(), [&](std::int32_t a, std::int32_t b) {
        return sum[a].squaredNorm() > sum[b].squaredNorm();
    });
    std::vector<Vec3> normals;
    normals.reserve(roots.size());
    for (std::int32_t r : roots) normals.push_back(sum[r].normalized());
    return normals;
}

// Unit directions of the hull's edges, longest first (ties by the edge's first appearance in the
// face list). A box axis along a hull edge holds, e.g., the prism-like hulls whose lateral faces
// are thin slivers. O(F log F).
std::vector<Vec3> edgeDirections(const ConvexPolytope& hull) {
    const std::vector<Vec3>& v = hull.vertices;
    std::vector<std::pair<Real, Vec3>> edges;
    for (const auto& t : hull.faces) {
        for (int e = 0; e < 3; ++e) {
            const std::int32_t a = t[e];
            const std::int32_t b = t[(e + 1) % 3];
            const Vec3 d = v[b] - v[a];
            const Real len = d.norm();
            // Each edge of a closed triangulation appears twice, once in each direction.
            if (a < b && len > 0) edges.emplace_back(len, d / len);
        }
    }
    std::stable_sort(edges.begin(), edges.end(),
                     [](const auto& x, const auto& y) { return x.first > y.first; });
    std::vector<Vec3> dirs;
    dirs.reserve(edges.size());
    for (const auto& e : edges) dirs.push_back(e.second);
    return dirs;
}

// Candidate axes after DiTO (Larsson & Källberg 2011, "Fast computation of tight-fitting oriented
// bounding boxes"): the extreme vertices along 7 fixed directions, the large triangle they span
// (farthest pair, then the point farthest from that line) and the two tetrahedra on it towards
// the farthest vertices on either side. The normals of these up to 7 triangles are returned;
// DiTO's frames (edge, normal, edge x normal) are all dominated by the exact 2-D rectangle
// around such a normal, so only the normals are needed. O(V).
std::vector<Vec3> ditoAxes(const std::vector<Vec3>& v) {
    const Vec3 origin = v[0];
    const Vec3 dirs[7] = {Vec3(1, 0, 0),  Vec3(0, 1, 0),  Vec3(0, 0, 1),  Vec3(1, 1, 1),
                          Vec3(1, 1, -1), Vec3(1, -1, 1), Vec3(1, -1, -1)};
    std::vector<Vec3> ext;
    Real size = 0;
    for (const Vec3& d : dirs) {
        std::size_t lo = 0;
        std::size_t hi = 0;
        for (std::size_t i = 1; i < v.size(); ++i) {
            if (d.dot(v[i] - origin) < d.dot(v[lo] - origin)) lo = i;
            if (d.dot(v[i] - origin) > d.dot(v[hi] - origin)) hi = i;
        }
        ext.push_back(v[lo] - origin);
        ext.push_back(v[hi] - origin);
        size = std::max(size, (v[hi] - v[lo]).norm());
    }
    std::vector<Vec3> axes;
    const Real tiny = Real(64) * kEpsilon * size;  // shorter lengths are rounding noise
    std::size_t pair = 0;
    for (std::size_t k = 1; k < 7; ++k) {
        if ((ext[2 * k + 1] - ext[2 * k]).squaredNorm() >
            (ext[2 * pair + 1] - ext[2 * pair]).squaredNorm()) {
            pair = k;
        }
    }
    const Vec3 p0 = ext[2 * pair];
    const Vec3 p1 = ext[2 * pair + 1];
    const Vec3 e0 = p1 - p0;
    if (e0.norm() <= tiny) return axes;
    const Vec3 u0 = e0.normalized();
    Vec3 p2 = p0;
    for (const Vec3& q : ext) {
        const Vec3 off = (q - p0) - u0 * u0.dot(q - p0);
        if (off.squaredNorm() > ((p2 - p0) - u0 * u0.dot(p2 - p0)).squaredNorm()) p2 = q;
    }
    const Vec3 n = e0.cross(p2 - p0);
    if (n.norm() <= tiny * e0.norm()) return axes;
    axes.push_back(n.normalized());
    Vec3 below = p0;
    Vec3 above = p0;
    for (const Vec3& p : v) {
        const Vec3 q = p - origin;
        if (n.dot(q - p0) < n.dot(below - p0)) below = q;
        if (n.dot(q - p0) > n.dot(above - p0)) above = q;
    }
    for (const Vec3& apex : {below, above}) {
        const Vec3 tri[3][2] = {{p0, p1}, {p1, p2}, {p2, p0}};
        for (const auto& t : tri) {
            const Vec3 m = (t[1] - t[0]).cross(apex - t[0]);
            if (m.norm() > tiny * size) axes.push_back(m.normalized());
        }
    }
    return axes;
}

// Keeps the smallest box over the candidates tried, in the order tried (strictly smaller wins, so
// the result is a deterministic function of the hull).
class TightObbSearch {
public:
    explicit TightObbSearch(const ConvexPolytope& hull) : hull_(hull), origin_(hull.vertices[0]) {
        const std::vector<Vec3>& v = hull.vertices;
        unit_.reserve(hull.faces.size());
        incident_.assign(v.size(), 0);
        for (const auto& t : hull.faces) {
            const Vec3 c = (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]);
            const Real len = c.norm();
            unit_.push_back(len > 0 && std::isfinite(len) ? Vec3(c / len) : Vec3::Zero());
            for (std::int32_t i : t) incident_[i] = 1;
        }
    }

    const std::vector<Vec3>& faceNormals() const { return unit_; }
    const Mat3& bestAxes() const { return best_.axes; }
    const Obb& best() const { return best_; }

    /// Evaluates the box on `axes` (orthonormal, right-handed).
    void tryFrame(const Mat3& axes) {
        Real volume = 0;
        const Obb box = boxOnAxes(axes, hull_.vertices, origin_, &volume);
        if (best_volume_ < 0 || volume < best_volume_) {
            best_ = box;
            best_volume_ = volume;
        }
    }

    /// The smallest box with one axis along unit `axis`: the hull projected on the plane normal
    /// to it, boxed by the minimum-area rectangle (exact for that axis, Freeman & Shapira 1975).
    /// False, and nothing tried, when `axis` repeats an axis tried before.
    bool tryAxis(const Vec3& axis) {
        for (const Vec3& a : tried_) {
            if (std::abs(a.dot(axis)) >= Real(1) - kSameAxisCos) return false;
        }
        tried_.push_back(axis);
        // Plane basis (b1, b2, axis), b1 normal to the axis and to its smallest coordinate.
        int k = 0;
        axis.cwiseAbs().minCoeff(&k);
        const Vec3 b1 = axis.cross(Vec3::Unit(k)).normalized();
        const Vec3 b2 = axis.cross(b1);
        markSilhouette(axis);
        points_.clear();
        for (std::size_t i = 0; i < hull_.vertices.size(); ++i) {
            if (side_[i] != 3 && incident_[i]) continue;
            const Vec3 q = hull_.vertices[i] - origin_;
            points_.push_back(Point2{b1.dot(q), b2.dot(q)});
        }
        const Rectangle2 rect = minAreaRectangle(convexHull2(points_));
        Mat3 axes;
        axes.col(0) = (rect.ux * b1 + rect.uy * b2).normalized();
        axes.col(1) = axis.cross(axes.col(0)).normalized();
        axes.col(2) = axes.col(0).cross(axes.col(1));
        tryFrame(axes);
        return true;
    }

private:
    // side_[i]: bit 1 when vertex i has an incident face facing along the axis (within the
    // silhouette slack), bit 2 when one faces against it. Both bits: on the silhouette, since an
    // extreme vertex of the projection has the in-plane direction in its normal cone.
    void markSilhouette(const Vec3& axis) {
        side_.assign(hull_.vertices.size(), 0);
        for (std::size_t f = 0; f < hull_.faces.size(); ++f) {
            const Real c = unit_[f].dot(axis);
            const std::uint8_t bits =
                (c >= -kSilhouetteCos ? 1 : 0) | (c <= kSilhouetteCos ? 2 : 0);
            for (std::int32_t i : hull_.faces[f]) side_[i] |= bits;
        }
    }

    const ConvexPolytope& hull_;
    Vec3 origin_;
    std::vector<Vec3> unit_;
    std::vector<std::uint8_t> incident_;
    std::vector<std::uint8_t> side_;
    std::vector<Point2> points_;
    std::vector<Vec3> tried_;
    Obb best_;
    Real best_volume_ = -1;
};

}  // namespace

Obb fitObbPrincipal(const ConvexPolytope& hull) {
    CDLAB_ASSERT(!hull.vertices.empty(), "OBB of an empty hull");
    return boxOnAxes(principalAxes(hull), hull.vertices, hull.vertices[0], nullptr);
}

Obb fitObbTight(const ConvexPolytope& hull) {
    CDLAB_ASSERT(!hull.vertices.empty(), "OBB of an empty hull");
    TightObbSearch search(hull);
    const Mat3 principal = principalAxes(hull);
    search.tryFrame(principal);
    for (int c = 0; c < 3; ++c) search.tryAxis(principal.col(c));
    for (int c = 0; c < 3; ++c) search.tryAxis(Vec3::Unit(c));
    std::size_t face_axes = 0;
    for (const Vec3& n : patchNormals(hull, search.faceNormals())) {
        if (face_axes == kMaxFaceAxes) break;
        if (search.tryAxis(n)) ++face_axes;
    }
    for (const Vec3& n : ditoAxes(hull.vertices)) search.tryAxis(n);
    std::size_t edge_axes = 0;
    for (const Vec3& d : edgeDirections(hull)) {
        if (edge_axes == kMaxEdgeAxes) break;
        if (search.tryAxis(d)) ++edge_axes;
    }
    // Coordinate descent on the best box: re-solve the 2-D problem about each of its own axes
    // (an axis tried before is skipped), until a round finds nothing new or smaller.
    for (int round = 0; round < kMaxRefineRounds; ++round) {
        const Mat3 axes = search.bestAxes();
        bool tried = false;
        for (int c = 0; c < 3; ++c) tried = search.tryAxis(axes.col(c)) || tried;
        if (!tried || search.bestAxes() == axes) break;
    }
    return search.best();
}

}  // namespace collision
