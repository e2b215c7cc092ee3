// collision/src/geometry/convex_hull.cpp -- quickhull (Barber, Dobkin, Huhdanpaa, ACM TOMS 22(4)
// 1996).
// Invariants: every live face is a CCW-from-outside triangle whose three neighbours are live
// faces sharing its edges (a closed 2-manifold); every unprocessed point lies in the outside set
// of exactly one live face and is more than `tol` above it. Points are processed in a fixed
// order (face index, then farthest point, ties to the lowest input index), so the output is a
// pure function of the input order.
#include "collision/geometry/convex_hull.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace collision {

namespace {

// Plane-distance tolerance = kToleranceFactor * eps * (max|x| + max|y| + max|z|) of the centred
// set. Barber 1996 §4 and Lloyd's quickhull3d use 3 eps times that sum as the rounding bound of a
// plane distance; the extra factor covers planes built from cross products of differences.
constexpr Real kToleranceFactor = 32;

struct Face {
    std::array<std::int32_t, 3> v{};    // vertex indices into the (centred) point array
    std::array<std::int32_t, 3> nbr{};  // nbr[i] shares edge v[i] -> v[(i+1)%3]
    Vec3 normal = Vec3::Zero();         // unit, outward
    Real offset = 0;                    // plane: normal . x = offset
    std::vector<std::int32_t> outside;  // points strictly above (> tol), ascending index
    bool alive = true;
    bool visible = false;
};

struct HorizonEdge {
    std::int32_t face;  // the visible face
    int edge;           // its edge index: v[edge] -> v[edge + 1]
};

class Quickhull {
public:
    Quickhull(const std::vector<Vec3>& pts, Real tol) : p_(pts), tol_(tol) {}

    // Builds the hull; false with `error` set when the set is degenerate or numerics fail.
    bool build(std::string& error);
    // Live faces as vertex-index triples (indices into the input array).
    std::vector<std::array<std::int32_t, 3>> liveFaces() const;

private:
    Real distance(const Face& f, std::int32_t i) const { return f.normal.dot(p_[i]) - f.offset; }
    void setPlane(Face& f, const Vec3& fallback_normal) const;
    bool initialSimplex(std::string& error);
    bool addPoint(std::int32_t face_index, std::int32_t eye, std::string& error);
    void collectVisible(std::int32_t seed, std::int32_t eye, std::vector<std::int32_t>& visible,
                        std::vector<HorizonEdge>& horizon, Real threshold);
    bool orderHorizon(std::vector<HorizonEdge>& horizon) const;
    int edgeIndex(const Face& f, std::int32_t a, std::int32_t b) const;

    const std::vector<Vec3>& p_;
    Real tol_;
    std::vector<Face> faces_;
};

void Quickhull::setPlane(Face& f, const Vec3& fallback_normal) const {
    const Vec3& a = p_[f.v[0]];
    const Vec3& b = p_[f.v[1]];
    const Vec3& c = p_[f.v[2]];
    const Vec3 n = (b - a).cross(c - a);
    const Real len = n.norm();
    // A sliver (the eye point on the line of a horizon edge) has no plane of its own; it lies in
    // its neighbour's plane, so it borrows that normal. The extreme-point pass removes the
    // middle vertex afterwards.
    const Real edge2 =
        std::max({(b - a).squaredNorm(), (c - a).squaredNorm(), (c - b).squaredNorm()});
    if (len > kToleranceFactor * kEpsilon * edge2 && std::isfinite(len)) {
        f.normal = n / len;
    } else {
        f.normal = fallback_normal;
    }
    // Offset through the centroid: rounding is then symmetric over the three vertices.
    f.offset = f.normal.dot((a + b + c) / Real(3));
}

int Quickhull::edgeIndex(const Face& f, std::int32_t a, std::int32_t b) const {
    for (int i = 0; i < 3; ++i) {
        if (f.v[i] == a && f.v[(i + 1) % 3] == b) return i;
    }
    return -1;
}

bool Quickhull::initialSimplex(std::string& error) {
    const auto n = static_cast<std::int32_t>(p_.size());
    // The two farthest apart of the six axis-extreme points (Barber 1996 §3).
    std::array<std::int32_t, 6> ext{};
    for (int axis = 0; axis < 3; ++axis) {
        std::int32_t lo = 0;
        std::int32_t hi = 0;
        for (std::int32_t i = 1; i < n; ++i) {
            if (p_[i][axis] < p_[lo][axis]) lo = i;
            if (p_[i][axis] > p_[hi][axis]) hi = i;
        }
        ext[2 * axis] = lo;
        ext[2 * axis + 1] = hi;
    }
    std::int32_t i0 = ext[0];
    std::int32_t i1 = ext[1];
    Real best = -1;
    for (int a = 0; a < 6; ++a) {
        for (int b = a + 1; b < 6; ++b) {
            const Real d = (p_[ext[a]] - p_[ext[b]]).squaredNorm();
            if (d > best) {
                best = d;
                i0 = ext[a];
                i1 = ext[b];
            }
        }
    }
    if (!(std::sqrt(best) > tol_)) {
        error = "all points coincide";
        return false;
    }
    // Farthest from the line i0-i1.
    const Vec3 dir = (p_[i1] - p_[i0]).normalized();
    std::int32_t i2 = -1;
    best = -1;
    for (std::int32_t i = 0; i < n; ++i) {
        const Vec3 r = p_[i] - p_[i0];
        const Real d = (r - dir * dir.dot(r)).squaredNorm();
        if (d > best) {
            best = d;
            i2 = i;
        }
    }
    if (!(std::sqrt(best) > tol_)) {
        error = "points are collinear";
        return false;
    }
    // Farthest from the plane i0-i1-i2.
    const Vec3 nrm = (p_[i1] - p_[i0]).cross(p_[i2] - p_[i0]).normalized();
    std::int32_t i3 = -1;
    best = -1;
    for (std::int32_t i = 0; i < n; ++i) {
        const Real d = std::abs(nrm.dot(p_[i] - p_[i0]));
        if (d > best) {
            best = d;
            i3 = i;
        }
    }
    if (!(best > tol_)) {
        error = "points are coplanar";
        return false;
    }
    // Orient so that i3 is below the base triangle (i0, i1, i2) seen from outside.
    if (nrm.dot(p_[i3] - p_[i0]) > 0) std::swap(i1, i2);
    // Faces: base (0,1,2) and the three sides (a, b, apex) with the base edge reversed.
    //   f0 = (i0,i1,i2); f1 = (i1,i0,i3); f2 = (i2,i1,i3); f3 = (i0,i2,i3)
    faces_.resize(4);
    faces_[0].v = {i0, i1, i2};
    faces_[1].v = {i1, i0, i3};
    faces_[2].v = {i2, i1, i3};
    faces_[3].v = {i0, i2, i3};
    // Neighbours by matching reversed edges.
    for (std::int32_t f = 0; f < 4; ++f) {
        for (int e = 0; e < 3; ++e) {
            const std::int32_t a = faces_[f].v[e];
            const std::int32_t b = faces_[f].v[(e + 1) % 3];
            for (std::int32_t g = 0; g < 4; ++g) {
                if (g != f && edgeIndex(faces_[g], b, a) >= 0) faces_[f].nbr[e] = g;
            }
        }
    }
    for (Face& f : faces_) setPlane(f, Vec3::UnitX());
    // Assign every other point to the first face it is above.
    for (std::int32_t i = 0; i < n; ++i) {
        if (i == i0 || i == i1 || i == i2 || i == i3) continue;
        for (Face& f : faces_) {
            if (distance(f, i) > tol_) {
                f.outside.push_back(i);
                break;
            }
        }
    }
    return true;
}

// Depth-first flood from `seed` over faces the eye sees (distance > threshold); the horizon is
// every edge between a visible and a non-visible face, listed from the visible side.
void Quickhull::collectVisible(std::int32_t seed, std::int32_t eye,
                               std::vector<std::int32_t>& visible,
                               std::vector<HorizonEdge>& horizon, Real threshold) {
    std::vector<std::int32_t> stack{seed};
    faces_[seed].visible = true;
    visible.push_back(seed);
    while (!stack.empty()) {
        const std::int32_t f = stack.back();
        stack.pop_back();
        for (int e = 0; e < 3; ++e) {
            const std::int32_t g = faces_[f].nbr[e];
            if (faces_[g].visible) continue;
            if (distance(faces_[g], eye) > threshold) {
                faces_[g].visible = true;
                visible.push_back(g);
                stack.push_back(g);
            }
        }
    }
    horizon.clear();
    for (const std::int32_t f : visible) {
        for (int e = 0; e < 3; ++e) {
            if (!faces_[faces_[f].nbr[e]].visible) horizon.push_back({f, e});
        }
    }
}

// Chains the horizon edges head to tail. False when they do not form one simple loop (the
// visible region is not a disc, which only rounding can cause).
bool Quickhull::orderHorizon(std::vector<HorizonEdge>& horizon) const {
    const std::size_t m = horizon.size();
    if (m < 3) return false;
    auto tail = [&](const HorizonEdge& h) { return faces_[h.face].v[h.edge]; };
    auto head = [&](const HorizonEdge& h) { return faces_[h.face].v[(h.edge + 1) % 3]; };
    std::vector<HorizonEdge> ordered;
    ordered.reserve(m);
    ordered.push_back(horizon[0]);
    std::vector<bool> used(m, false);
    used[0] = true;
    for (std::size_t k = 1; k < m; ++k) {
        const std::int32_t want = head(ordered.back());
        std::size_t found = m;
        for (std::size_t j = 0; j < m; ++j) {
            if (used[j] || tail(horizon[j]) != want) continue;
            if (found != m) return false;  // two edges leave one vertex: not simple
            found = j;
        }
        if (found == m) return false;
        used[found] = true;
        ordered.push_back(horizon[found]);
    }
    if (head(ordered.back()) != tail(ordered.front())) return false;
    horizon = std::move(ordered);
    return true;
}

bool Quickhull::addPoint(std::int32_t face_index, std::int32_t eye, std::string& error) {
    std::vector<std::int32_t> visible;
    std::vector<HorizonEdge> horizon;
    collectVisible(face_index, eye, visible, horizon, tol_);
    if (!orderHorizon(horizon)) {
        // Rounding made the visible region a non-disc: also take the faces the eye is coplanar
        // with (distance > -tol). This only swaps coplanar triangles for other coplanar ones.
        for (const std::int32_t f : visible) faces_[f].visible = false;
        visible.clear();
        collectVisible(face_index, eye, visible, horizon, -tol_);
        if (!orderHorizon(horizon)) {
            for (const std::int32_t f : visible) faces_[f].visible = false;
            error = "numerical failure: the horizon of a point is not a simple loop";
            return false;
        }
    }
    // Cone of new faces (a, b, eye) over the horizon edges a -> b, in loop order.
    const auto first_new = static_cast<std::int32_t>(faces_.size());
    const auto m = static_cast<std::int32_t>(horizon.size());
    if (faces_.capacity() < faces_.size() + horizon.size()) {
        faces_.reserve(2 * (faces_.size() + horizon.size()));  // geometric: amortised O(1)
    }
    for (std::int32_t k = 0; k < m; ++k) {
        const Face& vf = faces_[horizon[k].face];
        const int e = horizon[k].edge;
        const std::int32_t a = vf.v[e];
        const std::int32_t b = vf.v[(e + 1) % 3];
        const std::int32_t outer = vf.nbr[e];
        Face nf;
        nf.v = {a, b, eye};
        nf.nbr = {outer, first_new + (k + 1) % m, first_new + (k + m - 1) % m};
        const Vec3 fallback = faces_[outer].normal;
        setPlane(nf, fallback);
        const int oe = edgeIndex(faces_[outer], b, a);
        faces_[outer].nbr[oe] = first_new + k;
        faces_.push_back(std::move(nf));
    }
    // Re-home the outside points of the removed faces (ascending order kept per face).
    std::vector<std::int32_t> orphans;
    for (const std::int32_t f : visible) {
        for (const std::int32_t i : faces_[f].outside) {
            if (i != eye) orphans.push_back(i);
        }
        faces_[f].outside.clear();
        faces_[f].outside.shrink_to_fit();
        faces_[f].alive = false;
        faces_[f].visible = false;
    }
    std::sort(orphans.begin(), orphans.end());
    for (const std::int32_t i : orphans) {
        for (std::int32_t f = first_new; f < first_new + m; ++f) {
            if (distance(faces_[f], i) > tol_) {
                faces_[f].outside.push_back(i);
                break;
            }
        }
        // Not above any new face: inside the hull now, dropped.
    }
    return true;
}

bool Quickhull::build(std::string& error) {
    if (!initialSimplex(error)) return false;
    // New faces are appended and only new faces receive points, so one forward scan visits
    // every face that ever has an outside set.
    for (std::size_t f = 0; f < faces_.size(); ++f) {
        if (!faces_[f].alive || faces_[f].outside.empty()) continue;
        std::int32_t eye = faces_[f].outside[0];
        Real far = distance(faces_[f], eye);
        for (const std::int32_t i : faces_[f].outside) {
            const Real d = distance(faces_[f], i);
            if (d > far) {
                far = d;
                eye = i;
            }
        }
        if (!addPoint(static_cast<std::int32_t>(f), eye, error)) return false;
    }
    return true;
}

std::vector<std::array<std::int32_t, 3>> Quickhull::liveFaces() const {
    std::vector<std::array<std::int32_t, 3>> out;
    for (const Face& f : faces_) {
        if (f.alive) out.push_back(f.v);
    }
    return out;
}

// A vertex is extreme when the mean of its incident unit face normals, d, puts it strictly above
// all its neighbours (by > tol). For a convex polytope a vertex above all its edge neighbours
// maximises d (the simplex-method argument), and d lies inside the normal cone of a true vertex;
// a point inside a flat facet or on a straight edge has a neighbour level with it along any d.
std::vector<bool> extremeVertices(const std::vector<Vec3>& pts,
                                  const std::vector<std::array<std::int32_t, 3>>& faces, Real tol) {
    const std::size_t n = pts.size();
    std::vector<Vec3> dir(n, Vec3::Zero());
    for (const auto& f : faces) {
        const Vec3 nrm = (pts[f[1]] - pts[f[0]]).cross(pts[f[2]] - pts[f[0]]);
        const Real len = nrm.norm();
        if (!(len > 0)) continue;
        for (const std::int32_t v : f) dir[v] += nrm / len;
    }
    std::vector<bool> used(n, false);
    std::vector<bool> extreme(n, true);
    for (const auto& f : faces) {
        for (int k = 0; k < 3; ++k) {
            const std::int32_t v = f[k];
            used[v] = true;
            const Real len = dir[v].norm();
            if (!(len > 0)) {
                extreme[v] = false;
                continue;
            }
            const Vec3 d = dir[v] / len;
            for (int j = 1; j < 3; ++j) {
                const std::int32_t w = f[(k + j) % 3];
                if (!(d.dot(pts[v] - pts[w]) > tol)) extreme[v] = false;
            }
        }
    }
    for (std::size_t i = 0; i < n; ++i) extreme[i] = extreme[i] && used[i];
    return extreme;
}

}  // namespace

ConvexHullOutput computeConvexHull(const std::vector<Vec3>& points) {
    ConvexHullOutput out;
    if (points.size() < 4) {
        out.error = "convex hull needs at least 4 points, got " + std::to_string(points.size());
        return out;
    }
    if (points.size() > static_cast<std::size_t>(INT32_MAX)) {
        out.error = "too many points";
        return out;
    }
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (!points[i].allFinite()) {
            out.error = "point " + std::to_string(i) + " is not finite (NaN or Inf)";
            return out;
        }
    }
    // Centre on the bounding box so that rounding depends on the set's extent, not on its
    // distance from the origin (a unit set at 1e6 keeps a 1e-15-relative tolerance).
    Vec3 lo = points[0];
    Vec3 hi = points[0];
    for (const Vec3& p : points) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    const Vec3 centre = (lo + hi) * Real(0.5);
    std::vector<Vec3> pts;
    std::vector<std::int32_t> original;  // pts[i] is points[original[i]]
    pts.reserve(points.size());
    original.reserve(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
        pts.push_back(points[i] - centre);
        original.push_back(static_cast<std::int32_t>(i));
    }
    Vec3 max_abs = Vec3::Zero();
    for (const Vec3& p : pts) max_abs = max_abs.cwiseMax(p.cwiseAbs());
    const Real tol = kToleranceFactor * kEpsilon * max_abs.sum();

    // Quickhull, then drop vertices that are not extreme (points in a flat facet or on a
    // straight edge that were added before the facet was complete) and rebuild from the rest.
    // Each round removes at least one point, so this terminates.
    std::vector<std::array<std::int32_t, 3>> faces;
    for (;;) {
        Quickhull qh(pts, tol);
        std::string error;
        if (!qh.build(error)) {
            out.error = error;
            return out;
        }
        faces = qh.liveFaces();
        const std::vector<bool> extreme = extremeVertices(pts, faces, tol);
        std::vector<Vec3> kept;
        std::vector<std::int32_t> kept_original;
        bool dropped_referenced = false;
        for (std::size_t i = 0; i < pts.size(); ++i) {
            if (extreme[i]) {
                kept.push_back(pts[i]);
                kept_original.push_back(original[i]);
            }
        }
        for (const auto& f : faces) {
            for (const std::int32_t v : f) dropped_referenced |= !extreme[v];
        }
        if (!dropped_referenced) break;
        if (kept.size() < 4) {
            out.error = "points are coplanar";
            return out;
        }
        pts = std::move(kept);
        original = std::move(kept_original);
    }

    // Compact: vertices in ascending input order, faces re-indexed.
    std::vector<std::int32_t> remap(pts.size(), -1);
    for (const auto& f : faces) {
        for (const std::int32_t v : f) remap[v] = 0;
    }
    std::vector<std::pair<std::int32_t, std::int32_t>> by_input;  // (input index, local index)
    for (std::size_t i = 0; i < pts.size(); ++i) {
        if (remap[i] == 0) by_input.emplace_back(original[i], static_cast<std::int32_t>(i));
    }
    std::sort(by_input.begin(), by_input.end());
    for (std::size_t k = 0; k < by_input.size(); ++k) {
        remap[by_input[k].second] = static_cast<std::int32_t>(k);
        out.hull.vertices.push_back(points[by_input[k].first]);
    }
    out.hull.faces.reserve(faces.size());
    for (const auto& f : faces) out.hull.faces.push_back({remap[f[0]], remap[f[1]], remap[f[2]]});
    out.ok = true;
    return out;
}

}  // namespace collision
