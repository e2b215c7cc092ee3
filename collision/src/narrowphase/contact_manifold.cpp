// collision/src/narrowphase/contact_manifold.cpp -- the manifold of two touching polytope faces
// (box or hull, other than box-box): each shape's face most aligned with the normal, one clipped
// against the other (Sutherland-Hodgman), reduced to four points.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "collision/assert.h"
#include "narrowphase/contact_pairs.h"

namespace collision::contact_pairs {

namespace {

// Polygons up to this many vertices are clipped; larger faces fall back to one point.
constexpr int kMaxPolygon = 32;
// A face is the contact face when its normal is within this of the contact normal (cosine).
constexpr Real kFaceAlignment = Real(1) - Real(1e-12);

struct Polygon {
    std::array<Vec3, kMaxPolygon> v;  // the first n are set
    int n = 0;
    Vec3 normal = Vec3::Zero();  // unit, outward
    Real offset = 0;             // normal . v for every vertex
    Real alignment = -2;         // normal . direction
};

// The face of a box or hull (own frame) whose outward normal is closest to unit `dir`, as a
// polygon ordered counter-clockwise around its normal; coplanar hull triangles are merged.
// Returns false (with out.alignment set) without building the polygon when the alignment is
// below `min_alignment`.
bool facePolygon(const Shape& shape, const Vec3& dir, Real tol, Real min_alignment, Polygon& out) {
    out.n = 0;
    out.alignment = -2;
    if (shape.type == ShapeType::Box) {
        int k = 0;
        dir.cwiseAbs().maxCoeff(&k);
        const Real s = signOrPlus(dir[k]);
        const Vec3& h = shape.half_extents;
        const int u = (k + 1) % 3;
        const int w = (k + 2) % 3;
        const std::array<Real, 4> su{-1, 1, 1, -1};
        const std::array<Real, 4> sw{-1, -1, 1, 1};
        for (int c = 0; c < 4; ++c) {
            Vec3 p;
            p[k] = s * h[k];
            p[u] = su[static_cast<std::size_t>(c)] * h[u];
            p[w] = sw[static_cast<std::size_t>(c)] * h[w];
            out.v[static_cast<std::size_t>(s > 0 ? c : 3 - c)] = p;  // CCW around s e_k
        }
        out.n = 4;
        out.normal = s * Vec3::Unit(k);
        out.offset = h[k];  // normal . vertex = s * (s h_k)
        out.alignment = out.normal.dot(dir);
        return out.alignment >= min_alignment;
    }
    if (!shape.hull) return false;
    const ConvexPolytope& hull = *shape.hull;
    int best = -1;
    Vec3 best_normal = Vec3::Zero();
    for (std::size_t f = 0; f < hull.faces.size(); ++f) {
        const Vec3& a = hull.vertices[static_cast<std::size_t>(hull.faces[f][0])];
        const Vec3 nrm = (hull.vertices[static_cast<std::size_t>(hull.faces[f][1])] - a)
                             .cross(hull.vertices[static_cast<std::size_t>(hull.faces[f][2])] - a);
        const Real len = nrm.norm();
        if (!(len > 0)) continue;
        const Real al = nrm.dot(dir) / len;
        if (al > out.alignment) {
            out.alignment = al;
            best = static_cast<int>(f);
            best_normal = nrm / len;
        }
    }
    if (best < 0 || out.alignment < min_alignment) return false;
    out.normal = best_normal;
    out.offset = best_normal.dot(hull.vertices[static_cast<std::size_t>(hull.faces[best][0])]);
    // Every hull vertex on the plane belongs to the (convex) face polygon.
    Vec3 centre = Vec3::Zero();
    for (const Vec3& p : hull.vertices) {
        if (std::abs(best_normal.dot(p) - out.offset) <= tol) {
            if (out.n >= kMaxPolygon) return false;
            out.v[static_cast<std::size_t>(out.n++)] = p;
            centre += p;
        }
    }
    if (out.n < 3) return false;
    centre /= Real(out.n);
    int axis = 0;
    best_normal.cwiseAbs().minCoeff(&axis);
    const Vec3 e1 = best_normal.cross(Vec3::Unit(axis)).normalized();
    const Vec3 e2 = best_normal.cross(e1);
    std::array<Real, kMaxPolygon> angle{};
    std::array<int, kMaxPolygon> order{};
    for (int i = 0; i < out.n; ++i) {
        const Vec3 d = out.v[static_cast<std::size_t>(i)] - centre;
        // Pseudo-angle in [-2, 2), monotonic in atan2(y, x) and far cheaper: only the order
        // matters.
        const Real x = d.dot(e1);
        const Real y = d.dot(e2);
        const Real r = std::abs(x) + std::abs(y);
        const Real t = r > 0 ? x / r : Real(1);
        angle[static_cast<std::size_t>(i)] = y < 0 ? t - 1 : 1 - t;
        order[static_cast<std::size_t>(i)] = i;
    }
    std::sort(order.begin(), order.begin() + out.n, [&](int x, int y) {
        const Real ax = angle[static_cast<std::size_t>(x)];
        const Real ay = angle[static_cast<std::size_t>(y)];
        return ax < ay || (ax == ay && x < y);
    });
    std::array<Vec3, kMaxPolygon> sorted{};
    for (int i = 0; i < out.n; ++i) {
        sorted[static_cast<std::size_t>(i)] =
            out.v[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
    }
    out.v = sorted;
    return true;
}

// Sutherland-Hodgman (RTCD 8.3.4) against the half-space m . x <= c.
int clipByPlane(const std::array<Vec3, 2 * kMaxPolygon>& in, int n, const Vec3& m, Real c,
                std::array<Vec3, 2 * kMaxPolygon>& out) {
    int k = 0;
    for (int i = 0; i < n; ++i) {
        const Vec3& p = in[static_cast<std::size_t>(i)];
        const Vec3& q = in[static_cast<std::size_t>(i + 1 == n ? 0 : i + 1)];
        const Real dp = m.dot(p) - c;
        const Real dq = m.dot(q) - c;
        if (dp <= 0 && k < 2 * kMaxPolygon) out[static_cast<std::size_t>(k++)] = p;
        if (((dp < 0 && dq > 0) || (dp > 0 && dq < 0)) && k < 2 * kMaxPolygon) {
            out[static_cast<std::size_t>(k++)] = p + (dp / (dp - dq)) * (q - p);
        }
    }
    return k;
}

}  // namespace

// Face contact between two polytopes (A's frame, normal from A to B): the reference face (the
// face of A or B best aligned with the normal) clips the other shape's most anti-parallel face;
// points below the reference plane (depth >= -tolerance) form the manifold, reduced to 4 like
// box-box. Returns false (keep the single witness point) unless the reference face's normal is
// the contact normal, i.e. a face-vertex, face-edge or face-face contact.
bool polytopeManifold(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx,
                      Local& out) {
    const Real tol = kFeatureRelative * ctx.scale;
    Polygon face_a;
    Polygon face_b;
    const Vec3 n_in_b = rel.rotation.transpose() * (-out.normal);
    // Only a face aligned with the normal can be the reference: test both cheaply first, then
    // build the other side's (incident) face whatever its alignment.
    const bool a_ok = facePolygon(a, out.normal, tol, kFaceAlignment, face_a);
    const bool b_ok = facePolygon(b, n_in_b, tol, kFaceAlignment, face_b);
    if (!a_ok && !b_ok) return false;
    const bool a_is_reference = a_ok && (!b_ok || face_a.alignment >= face_b.alignment);
    if (a_is_reference && !b_ok && !facePolygon(b, n_in_b, tol, -2, face_b)) return false;
    if (!a_is_reference && !a_ok && !facePolygon(a, out.normal, tol, -2, face_a)) return false;
    // Put B's face in A's frame.
    for (int i = 0; i < face_b.n; ++i) {
        face_b.v[static_cast<std::size_t>(i)] =
            rel.rotation * face_b.v[static_cast<std::size_t>(i)] + rel.position;
    }
    face_b.normal = rel.rotation * face_b.normal;
    face_b.offset = face_b.normal.dot(face_b.v[0]);
    const Polygon& ref = a_is_reference ? face_a : face_b;
    const Polygon& inc = a_is_reference ? face_b : face_a;

    std::array<Vec3, 2 * kMaxPolygon> poly{};
    std::array<Vec3, 2 * kMaxPolygon> tmp{};
    int count = inc.n;
    for (int i = 0; i < inc.n; ++i)
        poly[static_cast<std::size_t>(i)] = inc.v[static_cast<std::size_t>(i)];
    for (int e = 0; e < ref.n && count > 0; ++e) {
        const Vec3& p = ref.v[static_cast<std::size_t>(e)];
        const Vec3& q = ref.v[static_cast<std::size_t>((e + 1) % ref.n)];
        const Vec3 m = (q - p).cross(ref.normal);  // outward side plane (CCW polygon)
        count = clipByPlane(poly, count, m, m.dot(p), tmp);
        poly = tmp;
    }
    std::array<Vec3, 2 * kMaxPolygon> points{};
    std::array<Real, 2 * kMaxPolygon> depths{};
    int kept = 0;
    // Depth along the contact normal to the reference plane, so that each point pair satisfies
    // point_b - point_a = -depth * normal exactly (the normals differ by < 1.5e-6 rad).
    const Real cos_ref = a_is_reference ? ref.normal.dot(out.normal) : -ref.normal.dot(out.normal);
    const Real max_depth = std::max(Real(0), -out.signed_distance) + tol;
    for (int i = 0; i < count; ++i) {
        const Vec3& p = poly[static_cast<std::size_t>(i)];
        const Real depth = (ref.offset - ref.normal.dot(p)) / cos_ref;
        // Deeper than the contact itself means beyond the far side of a thin reference shape
        // (the side planes bound the face's prism, not the shape): not a contact point.
        if (depth >= -ctx.tolerance && depth <= max_depth) {
            points[static_cast<std::size_t>(kept)] = p;
            depths[static_cast<std::size_t>(kept)] = depth;
            ++kept;
        }
    }
    if (kept == 0) return false;
    std::array<int, 4> chosen{};
    const int m = reduceManifold(points.data(), depths.data(), kept, out.normal, chosen);
    out.manifold_size = m;
    for (int i = 0; i < m; ++i) {
        const auto k = static_cast<std::size_t>(chosen[static_cast<std::size_t>(i)]);
        ManifoldPoint& mp = out.manifold[static_cast<std::size_t>(i)];
        mp.depth = std::max(depths[k], Real(0));
        // The incident point, and its projection onto the reference face along the normal.
        if (a_is_reference) {
            mp.point_b = points[k];
            mp.point_a = points[k] + depths[k] * out.normal;
        } else {
            mp.point_a = points[k];
            mp.point_b = points[k] - depths[k] * out.normal;
        }
    }
    return true;
}

}  // namespace collision::contact_pairs
