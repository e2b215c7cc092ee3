// collision/src/narrowphase/contact_box_box.cpp -- contact() of two boxes: the box SAT measure
// (box_sat.h, the one collide() decides from) with a bias towards face axes, and the manifold of
// the incident face clipped against the reference face (RTCD 8.3.4), reduced to four points.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "collision/assert.h"
#include "geometry/closest_points.h"
#include "narrowphase/contact_pairs.h"

namespace collision::contact_pairs {

namespace {

// Sutherland-Hodgman (RTCD 8.3.4): keeps the part of polygon `in` with coord[kAxis] * sign <=
// limit. The axis is a template parameter so the coordinates stay in registers.
template <int kAxis>
int clipPolygon(const std::array<Vec3, 8>& in, int n, Real sign, Real limit,
                std::array<Vec3, 8>& out) {
    int m = 0;
    for (int i = 0; i < n; ++i) {
        const Vec3& p = in[static_cast<std::size_t>(i)];
        const Vec3& q = in[static_cast<std::size_t>(i + 1 == n ? 0 : i + 1)];
        const Real dp = sign * p[kAxis] - limit;
        const Real dq = sign * q[kAxis] - limit;
        if (dp <= 0 && m < 8) out[static_cast<std::size_t>(m++)] = p;
        if ((dp < 0 && dq > 0) || (dp > 0 && dq < 0)) {
            const Real t = dp / (dp - dq);
            Vec3 x = p + t * (q - p);
            x[kAxis] = sign * limit;  // exactly on the plane
            if (m < 8) out[static_cast<std::size_t>(m++)] = x;
        }
    }
    return m;
}

// The polygon clipped to the slabs |coord[kA1]| <= h[kA1], then |coord[kA2]| <= h[kA2].
template <int kA1, int kA2>
int clipToSlabs(const Vec3& h, int n, std::array<Vec3, 8>& poly) {
    std::array<Vec3, 8> tmp;  // only the first n entries are read
    n = clipPolygon<kA1>(poly, n, 1, h[kA1], tmp);
    n = clipPolygon<kA1>(tmp, n, -1, h[kA1], poly);
    n = clipPolygon<kA2>(poly, n, 1, h[kA2], tmp);
    return clipPolygon<kA2>(tmp, n, -1, h[kA2], poly);
}

// Face contact: reference box R (half extents hr, its frame), reference face on axis k with
// outward sign s; incident box I (half extents hi) placed by i_in_r. Writes points of I inside
// the reference face's slab with their depths below the face (in [-tolerance, max_depth]), in
// R's frame.
int clipFaceContact(const Vec3& hr, int k, Real s, const Vec3& hi, const RelativePose& i_in_r,
                    Real tolerance, Real max_depth, std::array<Vec3, 8>& points,
                    std::array<Real, 8>& depths) {
    // Incident face: the face of I most anti-parallel to the reference normal.
    const Vec3 n_in_i = i_in_r.rotation.transpose() * (s * Vec3::Unit(k));
    int m = 0;
    n_in_i.cwiseAbs().maxCoeff(&m);
    const Real sm = -signOrPlus(n_in_i[m]);
    const int u = (m + 1) % 3;
    const int v = (m + 2) % 3;
    std::array<Vec3, 8> poly;  // only the first n entries are read
    const std::array<Real, 4> su{-1, 1, 1, -1};
    const std::array<Real, 4> sv{-1, -1, 1, 1};
    for (int c = 0; c < 4; ++c) {
        Vec3 corner;
        corner[m] = sm * hi[m];
        corner[u] = su[static_cast<std::size_t>(c)] * hi[u];
        corner[v] = sv[static_cast<std::size_t>(c)] * hi[v];
        poly[static_cast<std::size_t>(c)] = i_in_r.rotation * corner + i_in_r.position;
    }
    // The side slabs of the reference face, axes (k + 1) % 3 then (k + 2) % 3.
    const int n = k == 0   ? clipToSlabs<1, 2>(hr, 4, poly)
                  : k == 1 ? clipToSlabs<2, 0>(hr, 4, poly)
                           : clipToSlabs<0, 1>(hr, 4, poly);
    int kept = 0;
    for (int i = 0; i < n; ++i) {
        const Vec3& p = poly[static_cast<std::size_t>(i)];
        const Real depth = hr[k] - s * p[k];
        points[static_cast<std::size_t>(kept)] = p;  // kept <= i < 8: kept by the count
        depths[static_cast<std::size_t>(kept)] = depth;
        kept += static_cast<int>(depth >= -tolerance) & static_cast<int>(depth <= max_depth);
    }
    return kept;
}

}  // namespace

// Keeps at most 4 of n points: the deepest, the farthest from it, the one spanning the largest
// triangle with those two, and the one adding the most area outside that triangle (Gregorius,
// "Robust Contact Creation for Physics Simulations", GDC 2015). Returns the chosen indices.
int reduceManifold(const Vec3* p, const Real* depth, int n, const Vec3& normal,
                   std::array<int, 4>& chosen) {
    if (n <= 4) {
        for (int i = 0; i < n; ++i) chosen[static_cast<std::size_t>(i)] = i;
        return n;
    }
    // Each choice by selects, not branches: which point wins is data.
    auto at = [&](int i) -> const Vec3& { return p[i]; };
    int i0 = 0;
    for (int i = 1; i < n; ++i) i0 = depth[i] > depth[i0] ? i : i0;
    int i1 = -1;
    Real best = -1;
    for (int i = 0; i < n; ++i) {
        const Real d = (at(i) - at(i0)).squaredNorm();
        const bool better = i != i0 && d > best;
        best = better ? d : best;
        i1 = better ? i : i1;
    }
    int i2 = -1;
    Real best_area = -1;
    Real orientation = 1;
    for (int i = 0; i < n; ++i) {
        const Real area = (at(i1) - at(i0)).cross(at(i) - at(i0)).dot(normal);
        const bool better = i != i0 && i != i1 && std::abs(area) > best_area;
        best_area = better ? std::abs(area) : best_area;
        i2 = better ? i : i2;
        orientation = better ? signOrPlus(area) : orientation;
    }
    int i3 = -1;
    Real best_out = 0;
    const std::array<int, 3> tri{i0, i1, i2};
    for (int i = 0; i < n; ++i) {
        const bool other = i != i0 && i != i1 && i != i2;
        for (int e = 0; e < 3; ++e) {
            const Vec3& s = at(tri[static_cast<std::size_t>(e)]);
            const Vec3& t = at(tri[static_cast<std::size_t>((e + 1) % 3)]);
            // Negative signed area w.r.t. the triangle's orientation: outside edge e.
            const Real area = -orientation * (t - s).cross(at(i) - s).dot(normal);
            const bool better = other && area > best_out;
            best_out = better ? area : best_out;
            i3 = better ? i : i3;
        }
    }
    chosen = {i0, i1, i2, i3};
    return i3 < 0 ? 3 : 4;
}

namespace {

// The details from the SAT measure: the edge-edge closest points, or the reference face clipped
// against the incident one. False when the best axis proves a gap larger than the tolerance or
// the clipped manifold is empty (GJK/EPA then give the details). When true, the witness points
// are a copy of manifold entry `witness_entry`.
bool satDetails(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx,
                const BoxSatMeasure& sat, Local& out, int& witness_entry) {
    const Mat3& rot = rel.rotation;
    const Vec3& t = rel.position;
    const Vec3& ea = a.half_extents;
    const Vec3& eb = b.half_extents;
    const Real best_face = sat.face_sep;
    const int face_kind = sat.face_box;
    const int face_axis = sat.face_axis;
    const Real best_edge = sat.edge_sep;
    const int edge_i = sat.edge_a;
    const int edge_j = sat.edge_b;
    const Vec3& edge_axis = sat.edge_axis;
    const bool use_edge = best_edge > best_face + kEdgeBias * ctx.scale;
    const Real best = use_edge ? best_edge : best_face;
    if (best > ctx.tolerance) return false;
    const Real tol = kFeatureRelative * ctx.scale;

    if (use_edge) {
        const Vec3 n = signOrPlus(t.dot(edge_axis)) * edge_axis;
        // A's edge along axis i at the support signs of n; B's along its axis j at -n.
        Vec3 ca = ea.cwiseProduct(Vec3(signOrPlus(n.x()), signOrPlus(n.y()), signOrPlus(n.z())));
        const Vec3 n_b = rot.transpose() * (-n);
        Vec3 cb =
            eb.cwiseProduct(Vec3(signOrPlus(n_b.x()), signOrPlus(n_b.y()), signOrPlus(n_b.z())));
        Vec3 pa0 = ca;
        Vec3 pa1 = ca;
        pa0[edge_i] = -ea[edge_i];
        pa1[edge_i] = ea[edge_i];
        Vec3 pb0 = cb;
        Vec3 pb1 = cb;
        pb0[edge_j] = -eb[edge_j];
        pb1[edge_j] = eb[edge_j];
        pb0 = rot * pb0 + t;
        pb1 = rot * pb1 + t;
        const SegmentParameters st =
            closestSegmentSegment(pa0, pa1, pb0, pb1, kEpsilon * ctx.scale);
        out.normal = n;
        out.signed_distance = best;
        out.point_a = pa0 + st.s * (pa1 - pa0);
        out.point_b = pb0 + st.t * (pb1 - pb0);
        out.feature_a = boxFeature(ea, out.point_a, tol);
        out.feature_b = boxFeature(eb, toB(rel, out.point_b), tol);
        setSingleManifold(out);
        witness_entry = 0;
        return true;
    }

    std::array<Vec3, 8> points;  // only the first count entries are read
    std::array<Real, 8> depths;
    int count = 0;
    Vec3 n;
    // Points deeper than the contact lie beyond the far side of a thin reference box.
    const Real max_depth = std::max(Real(0), -best) + kFeatureRelative * ctx.scale;
    if (face_kind == 0) {
        const Real s = signOrPlus(t[face_axis]);
        n = s * Vec3::Unit(face_axis);
        count =
            clipFaceContact(ea, face_axis, s, eb, rel, ctx.tolerance, max_depth, points, depths);
    } else {
        const Vec3 axis = rot.col(face_axis);
        const Real s = signOrPlus(t.dot(axis));
        n = s * axis;
        // B is the reference: work in B's frame with A as the incident box.
        RelativePose a_in_b;
        a_in_b.rotation = rot.transpose();
        a_in_b.position = -(rot.transpose() * t);
        count = clipFaceContact(eb, face_axis, -s, ea, a_in_b, ctx.tolerance, max_depth, points,
                                depths);
        for (int i = 0; i < count; ++i) {
            points[static_cast<std::size_t>(i)] = rot * points[static_cast<std::size_t>(i)] + t;
        }
    }
    if (count == 0) return false;  // rounding at a grazing contact: let GJK/EPA answer
    std::array<int, 4> chosen{};
    const int kept = reduceManifold(points.data(), depths.data(), count, n, chosen);
    out.normal = n;
    out.signed_distance = best;
    out.manifold_size = kept;
    int deepest = 0;
    for (int m = 0; m < kept; ++m) {
        const auto i = static_cast<std::size_t>(chosen[static_cast<std::size_t>(m)]);
        const Real d = depths[i];
        ManifoldPoint& mp = out.manifold[static_cast<std::size_t>(m)];
        mp.depth = std::max(d, Real(0));
        if (face_kind == 0) {
            mp.point_b = points[i];
            mp.point_a = points[i] + d * n;  // projected onto A's reference face
        } else {
            mp.point_a = points[i];
            mp.point_b = points[i] - d * n;  // projected onto B's reference face
        }
        if (d > out.manifold[static_cast<std::size_t>(deepest)].depth) deepest = m;
    }
    out.point_a = out.manifold[static_cast<std::size_t>(deepest)].point_a;
    out.point_b = out.manifold[static_cast<std::size_t>(deepest)].point_b;
    out.feature_a = boxFeature(ea, out.point_a, tol);
    out.feature_b = boxFeature(eb, toB(rel, out.point_b), tol);
    witness_entry = deepest;
    return true;
}

}  // namespace

CollideOutput boxBoxWitness(const Shape& a, const Shape& b, const RelativePose& rel,
                            const Ctx& ctx, Local& out, int& witness_entry) {
    witness_entry = -1;
    // Clear overlaps (satBoxState's first test) need only the best axes.
    const BoxSatMeasure best =
        measureBoxSatBest(a.half_extents, rel.rotation, rel.position, b.half_extents,
                          -ctx.tolerance);
    if (best.max_sep + best.err_bound < -ctx.tolerance) {
        if (!satDetails(a, b, rel, ctx, best, out, witness_entry)) {
            convexConvex(a, b, rel, ctx, out);
        }
        CollideOutput decision;
        decision.state = ContactState::Penetrating;
        return decision;
    }
    const BoxSatMeasure sat =
        measureBoxSat(a.half_extents, rel.rotation, rel.position, b.half_extents);
    if (const std::optional<ContactState> proven = collide_pairs::satBoxState(sat, ctx.tolerance)) {
        if (!satDetails(a, b, rel, ctx, sat, out, witness_entry)) {
            convexConvex(a, b, rel, ctx, out);
        }
        CollideOutput decision;
        decision.state = *proven;
        return decision;
    }
    const CollideOutput decision =
        collide_pairs::refineBoxState(convexConvex(a, b, rel, ctx, out), sat, ctx.tolerance);
    // satDetails needs its best axis within the tolerance.
    if (sat.face_sep > ctx.tolerance && sat.edge_sep > ctx.tolerance) return decision;
    Local details;
    details.state = ContactState::Touching;
    int details_witness = -1;
    if (satDetails(a, b, rel, ctx, sat, details, details_witness)) {
        details.iterations = out.iterations;
        out = details;
        witness_entry = details_witness;
    }
    return decision;
}

CollideOutput boxBox(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx,
                     Local& out) {
    int witness_entry = -1;
    return boxBoxWitness(a, b, rel, ctx, out, witness_entry);
}

}  // namespace collision::contact_pairs
