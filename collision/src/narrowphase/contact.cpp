// collision/src/narrowphase/contact.cpp -- contact(): the full convex query (depth or distance,
// normal, witness points and features, manifold). Closed forms for sphere/capsule pairs and
// sphere-box (RTCD 5.1), SAT with a clipped manifold for box-box (Gottschalk 1996; RTCD 4.4.1,
// 8.3.4), GJK with witnesses and EPA (epa.h) for every other convex pair.
// Invariants: every routine computes in the canonically-first shape's frame and the world output
// is made once at the end; contact(b, a) runs the same routine on the same arguments as
// contact(a, b) and mirrors it, so the two are exact mirrors; the state is the touching
// convention of narrow_phase.h, and near its thresholds (|signed distance| within
// kReconcileBand * scale of the touching band) the state is taken from collide() itself, so the
// two can never disagree by rounding (the signed distance is then moved into the state's range,
// a change below kReconcileBand * scale).
#include "collision/narrowphase/contact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>

#include "collision/assert.h"
#include "geometry/closest_points.h"
#include "geometry/shape_measures.h"
#include "narrowphase/epa.h"
#include "narrowphase/gjk.h"

namespace collision {

namespace {

// Below kNormalRelative * scale a GJK distance is too small for (pb - pa) / d to be a reliable
// direction (its rounding error is ~ kEpsilon * scale / d radians): EPA decides the normal.
constexpr Real kNormalRelative = std::max(Real(1e-8), Real(1e3) * kEpsilon);
// A direction shorter than kDirectionRelative * scale is undefined (coincident centres etc.).
constexpr Real kDirectionRelative = Real(16) * kEpsilon;
// Witness points within kFeatureRelative * scale of a face plane / edge / vertex lie on it.
constexpr Real kFeatureRelative = std::max(Real(1e-9), Real(64) * kEpsilon);
// Width of the band around the touching thresholds where collide() decides the state.
constexpr Real kReconcileBand = Real(1e-6);
// Capsule axes closer to parallel than sin = kParallelSin have no common perpendicular to use.
constexpr Real kParallelSin = Real(1e-6);
// Box SAT: only the cross-product axes of exactly parallel edges (|e_a x e_b|^2 below
// kSatAxisMin, the smallest normal number) are skipped, as in collideBoxBox (which says why);
// an edge axis must beat the best face axis by kEdgeBias * scale to be chosen (faces give
// stable multi-point manifolds; Box2D / Bullet do the same).
constexpr Real kSatAxisMin = std::numeric_limits<Real>::min();
constexpr Real kEdgeBias = std::max(Real(1e-9), Real(64) * kEpsilon);

Real signOrPlus(Real x) { return x < 0 ? Real(-1) : Real(1); }

struct Ctx {
    Real scale = 0;
    Real tolerance = 0;
};

// The contact in A's frame (canonical order); world transform and mirroring happen once.
using Local = ContactOutput;

// Canonical order of two shapes: by type, then by a key of pose and dimensions, then by the
// hull's address (equal keys and hulls mean identical inputs, where the order does not matter).
bool canonicalLess(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
    if (a.type != b.type) return a.type < b.type;
    const std::array<Real, 12> ka{pa.position.x(),    pa.position.y(),    pa.position.z(),
                                  pa.orientation.w(), pa.orientation.x(), pa.orientation.y(),
                                  pa.orientation.z(), a.radius,           a.half_height,
                                  a.half_extents.x(), a.half_extents.y(), a.half_extents.z()};
    const std::array<Real, 12> kb{pb.position.x(),    pb.position.y(),    pb.position.z(),
                                  pb.orientation.w(), pb.orientation.x(), pb.orientation.y(),
                                  pb.orientation.z(), b.radius,           b.half_height,
                                  b.half_extents.x(), b.half_extents.y(), b.half_extents.z()};
    if (ka != kb) return ka < kb;
    return std::less<const ConvexPolytope*>()(a.hull.get(), b.hull.get());
}

// ---- Witness features (numbering in contact.h). ----

// Box edge parallel to axis k at the signs of the other two axes (i < j): 4k + bit_i + 2 bit_j.
std::int32_t boxEdgeIndex(int k, const Vec3& p) {
    const int i = k == 0 ? 1 : 0;
    const int j = k == 2 ? 1 : 2;
    return 4 * k + (p[i] > 0 ? 1 : 0) + (p[j] > 0 ? 2 : 0);
}

Feature boxFeature(const Vec3& half, const Vec3& p, Real tol) {
    int count = 0;
    int free_axis = -1;
    int face_axis = -1;
    for (int k = 0; k < 3; ++k) {
        if (std::abs(p[k]) >= half[k] - tol) {
            ++count;
            face_axis = k;
        } else {
            free_axis = k;
        }
    }
    if (count == 3) {
        return {FeatureType::Vertex,
                (p.x() > 0 ? 1 : 0) + (p.y() > 0 ? 2 : 0) + (p.z() > 0 ? 4 : 0)};
    }
    if (count == 2) return {FeatureType::Edge, boxEdgeIndex(free_axis, p)};
    if (count == 1) return {FeatureType::Face, 2 * face_axis + (p[face_axis] > 0 ? 1 : 0)};
    return {};
}

// Capsule features from the point on its core segment.
Feature capsuleFeature(Real half_height, const Vec3& core_point, Real tol) {
    if (core_point.y() <= -half_height + tol) return {FeatureType::Vertex, 0};
    if (core_point.y() >= half_height - tol) return {FeatureType::Vertex, 1};
    return {FeatureType::Edge, 0};
}

// Hull features: a vertex within tol; else the faces whose triangle holds p (within tol); one
// plane among them -> the lowest such face, two planes -> the edge they share.
Feature hullFeature(const ConvexPolytope& hull, const Vec3& p, Real tol) {
    for (std::size_t i = 0; i < hull.vertices.size(); ++i) {
        if ((hull.vertices[i] - p).squaredNorm() <= tol * tol) {
            return {FeatureType::Vertex, static_cast<std::int32_t>(i)};
        }
    }
    int first_face = -1;
    Vec3 first_normal = Vec3::Zero();
    for (std::size_t f = 0; f < hull.faces.size(); ++f) {
        const Vec3& v0 = hull.vertices[static_cast<std::size_t>(hull.faces[f][0])];
        const Vec3& v1 = hull.vertices[static_cast<std::size_t>(hull.faces[f][1])];
        const Vec3& v2 = hull.vertices[static_cast<std::size_t>(hull.faces[f][2])];
        const Vec3 n = (v1 - v0).cross(v2 - v0);
        const Real len = n.norm();
        if (!(len > 0)) continue;
        const Vec3 unit = n / len;
        if (std::abs(unit.dot(p - v0)) > tol) continue;
        // Inside the triangle: on the inner side of each edge, up to tol.
        const std::array<const Vec3*, 3> v{&v0, &v1, &v2};
        int on_edge = -1;
        bool inside = true;
        for (int e = 0; e < 3 && inside; ++e) {
            const Vec3& s = *v[static_cast<std::size_t>(e)];
            const Vec3& t = *v[static_cast<std::size_t>((e + 1) % 3)];
            const Vec3 edge = t - s;
            const Real edge_len = edge.norm();
            if (!(edge_len > 0)) continue;
            const Real inward = unit.cross(edge).dot(p - s) / edge_len;
            if (inward < -tol) inside = false;
            if (inward <= tol) on_edge = e;
        }
        if (!inside) continue;
        if (first_face < 0) {
            first_face = static_cast<int>(f);
            first_normal = unit;
            if (on_edge < 0) break;  // strictly inside one triangle
            continue;
        }
        if ((unit - first_normal).norm() > Real(1e-6)) {
            // Two distinct planes meet here: an edge of the polytope; name it by the first face.
            const Vec3& f0 = hull.vertices[static_cast<std::size_t>(hull.faces[first_face][0])];
            const Vec3& f1 = hull.vertices[static_cast<std::size_t>(hull.faces[first_face][1])];
            const Vec3& f2 = hull.vertices[static_cast<std::size_t>(hull.faces[first_face][2])];
            const std::array<const Vec3*, 3> w{&f0, &f1, &f2};
            int best_edge = 0;
            Real best_dist = std::numeric_limits<Real>::infinity();
            for (int e = 0; e < 3; ++e) {
                const Vec3& s = *w[static_cast<std::size_t>(e)];
                const Vec3 edge = *w[static_cast<std::size_t>((e + 1) % 3)] - s;
                const Real d = edge.cross(p - s).norm() / std::max(edge.norm(), tol);
                if (d < best_dist) {
                    best_dist = d;
                    best_edge = e;
                }
            }
            return {FeatureType::Edge, 3 * first_face + best_edge};
        }
    }
    if (first_face >= 0) return {FeatureType::Face, first_face};
    return {};
}

// Feature of a point of the shape's core (its own frame).
Feature coreFeature(const Shape& shape, const Vec3& core_point, Real tol) {
    switch (shape.type) {
        case ShapeType::Sphere:
            return {FeatureType::Face, 0};
        case ShapeType::Box:
            return boxFeature(shape.half_extents, core_point, tol);
        case ShapeType::Capsule:
            return capsuleFeature(shape.half_height, core_point, tol);
        case ShapeType::ConvexHull:
        case ShapeType::Mesh:
            return hullFeature(*shape.hull, core_point, tol);
    }
    return {};
}

Vec3 toB(const RelativePose& b_in_a, const Vec3& p_in_a) {
    return b_in_a.rotation.transpose() * (p_in_a - b_in_a.position);
}

void setSingleManifold(Local& out) {
    out.manifold_size = 1;
    out.manifold[0] =
        ManifoldPoint{out.point_a, out.point_b, std::max(Real(0), -out.signed_distance)};
}

// ---- Closed forms (A's frame). ----

// Both shapes reduce to points/segments inflated by radii: closest core points ca (on A) and cb
// (on B), direction from A to B. Witness points are the cores' points pushed out by the radii.
void roundContact(Real ra, Real rb, const Vec3& ca, const Vec3& cb, const Vec3& fallback_normal,
                  const Ctx& ctx, Local& out) {
    const Vec3 diff = cb - ca;
    const Real d = diff.norm();
    out.normal = d > kDirectionRelative * ctx.scale ? Vec3(diff / d) : fallback_normal;
    out.signed_distance = d - ra - rb;
    out.point_a = ca + ra * out.normal;
    out.point_b = cb - rb * out.normal;
}

void sphereSphere(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx,
                  Local& out) {
    // Coincident centres: A's local +x.
    roundContact(a.radius, b.radius, Vec3::Zero(), rel.position, Vec3::UnitX(), ctx, out);
    out.feature_a = {FeatureType::Face, 0};
    out.feature_b = {FeatureType::Face, 0};
}

// RTCD 5.1.2: sphere centre against the capsule's segment.
void sphereCapsule(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx,
                   Local& out) {
    const Vec3 centre_in_b = toB(rel, Vec3::Zero());
    const Real y = std::clamp(centre_in_b.y(), -b.half_height, b.half_height);
    const Vec3 on_axis = rel.rotation * Vec3(0, y, 0) + rel.position;
    // Centre on the axis: the sphere leaves along B's local -x (so the normal is B's +x).
    roundContact(a.radius, b.radius, Vec3::Zero(), on_axis, rel.rotation.col(0), ctx, out);
    out.feature_a = {FeatureType::Face, 0};
    if (centre_in_b.y() < -b.half_height) {
        out.feature_b = {FeatureType::Vertex, 0};
    } else if (centre_in_b.y() > b.half_height) {
        out.feature_b = {FeatureType::Vertex, 1};
    } else {
        out.feature_b = {FeatureType::Edge, 0};
    }
}

void capsuleCapsule(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx,
                    Local& out) {
    const Vec3 pa(0, -a.half_height, 0);
    const Vec3 qa(0, a.half_height, 0);
    const Vec3 axis_b = rel.rotation.col(1);
    const Vec3 pb = rel.position - b.half_height * axis_b;
    const Vec3 qb = rel.position + b.half_height * axis_b;
    const SegmentParameters st = closestSegmentSegment(pa, qa, pb, qb, kEpsilon * ctx.scale);
    const Vec3 ca = pa + st.s * (qa - pa);
    const Vec3 cb = pb + st.t * (qb - pb);
    // Crossing axes: the common perpendicular (towards B's centre); parallel axes: the component
    // of B's centre off A's axis, else A's local +x.
    Vec3 fallback = Vec3::UnitY().cross(axis_b);
    if (fallback.norm() > kParallelSin) {
        fallback.normalize();
    } else {
        fallback = Vec3(rel.position.x(), 0, rel.position.z());
        const Real len = fallback.norm();
        fallback = len > kDirectionRelative * ctx.scale ? Vec3(fallback / len) : Vec3::UnitX();
    }
    if (fallback.dot(rel.position) < 0) fallback = -fallback;
    roundContact(a.radius, b.radius, ca, cb, fallback, ctx, out);
    const Real tol = kFeatureRelative * ctx.scale;
    out.feature_a = capsuleFeature(a.half_height, ca, tol);
    out.feature_b = capsuleFeature(b.half_height, toB(rel, cb), tol);
}

// RTCD 5.1.3: the sphere centre clamped to the box (box frame); inside, the nearest face.
void sphereBox(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx,
               Local& out) {
    const Vec3 c = toB(rel, Vec3::Zero());
    const Vec3& h = b.half_extents;
    const Vec3 q = c.cwiseMax(-h).cwiseMin(h);
    const Vec3 outside = c - q;
    const Real tol = kFeatureRelative * ctx.scale;
    out.feature_a = {FeatureType::Face, 0};
    if (!outside.isZero()) {
        const Real d = outside.norm();
        const Vec3 n_b = -outside / d;  // from the sphere towards the box, B's frame
        out.normal = rel.rotation * n_b;
        out.signed_distance = d - a.radius;
        out.point_a = a.radius * out.normal;
        out.point_b = rel.rotation * q + rel.position;
        // Only the clamped coordinates lie on the box boundary.
        Vec3 probe = q;
        for (int k = 0; k < 3; ++k) {
            if (outside[k] == 0) probe[k] = std::clamp(q[k], -h[k] + 2 * tol, h[k] - 2 * tol);
        }
        out.feature_b = boxFeature(h, probe, tol);
        return;
    }
    // Inside: leave through the nearest face (ties: lowest axis; sign(0) = +).
    int k = 0;
    const Vec3 gap = h - c.cwiseAbs();
    gap.minCoeff(&k);
    const Real s = signOrPlus(c[k]);
    out.normal = rel.rotation * Vec3(-s * Vec3::Unit(k));
    out.signed_distance = -(gap[k] + a.radius);
    out.point_a = a.radius * out.normal;
    Vec3 on_face = c;
    on_face[k] = s * h[k];
    out.point_b = rel.rotation * on_face + rel.position;
    out.feature_b = {FeatureType::Face, 2 * k + (s > 0 ? 1 : 0)};
}

// ---- GJK + EPA for any convex pair (A's frame). ----

// Near-touching pairs (gap or depth below kNormalRelative * scale): B is shifted into A by
// kShiftRelative * scale along a trial normal, so the cores overlap far above rounding, and GJK +
// EPA answer there: EPA's normal is a face normal of A - B made from support-point differences
// (exact to rounding), not a direction through a rounding-sized gap. The shift is repeated along
// the new normal until it no longer changes; then the witnesses shifted back satisfy
// point_b - point_a = separation * normal with separation = shift * (trial . normal) - depth.
constexpr Real kShiftRelative = Real(4) * kNormalRelative;
constexpr int kShiftRounds = 4;
constexpr Real kSameNormal = Real(1e-12);

struct Shifted {
    Vec3 normal;
    Real separation;
    Vec3 core_a;
    Vec3 core_b;
};

bool shiftedEpa(const ConvexCore& ca, const ConvexCore& cb, const RelativePose& rel,
                const Vec3& trial, Real scale, Shifted& out, std::int32_t& iterations) {
    const Real shift = kShiftRelative * scale;
    // A rounding-sized gap or depth leaves the trial normal arbitrary, even pointing from B to A:
    // then shifting along it separates the cores, and its opposite is tried.
    Vec3 dir = trial;
    bool flipped = false;
    for (int round = 0; round < kShiftRounds; ++round) {
        RelativePose moved = rel;
        moved.position -= shift * dir;
        const GjkWitnessOutput g = gjkWitness(ca, cb, moved, scale);
        iterations += g.iterations;
        EpaOutput e;
        if (g.state == GjkState::Overlapping) {
            e = epaPenetration(ca, cb, moved, g.simplex, scale);
            iterations += e.iterations;
        }
        if (e.state != EpaState::Converged || !(e.depth > 0)) {
            if (round > 0 || flipped) return false;
            dir = -dir;
            flipped = true;
            --round;
            continue;
        }
        if ((e.normal - dir).norm() <= kSameNormal) {
            out.normal = e.normal;
            out.separation = shift * dir.dot(e.normal) - e.depth;
            out.core_a = e.point_a;
            out.core_b = e.point_b + shift * dir;
            return true;
        }
        dir = e.normal;
    }
    return false;
}

void generic(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx, Local& out) {
    const ConvexCore ca = ConvexCore::fromShape(a);
    const ConvexCore cb = ConvexCore::fromShape(b);
    const Real radii = ca.radius + cb.radius;
    const GjkWitnessOutput g = gjkWitness(ca, cb, rel, ctx.scale);
    out.iterations = g.iterations;
    Vec3 core_a;
    Vec3 core_b;
    if (g.state == GjkState::Separated && g.distance > kNormalRelative * ctx.scale) {
        core_a = g.point_a;
        core_b = g.point_b;
        out.normal = (core_b - core_a).normalized();  // length ~ distance > 0, checked above
        out.signed_distance = g.distance - radii;
    } else if (g.state == GjkState::Failed) {
        out.state = ContactState::Failed;
        return;
    } else {
        const EpaOutput e = epaPenetration(ca, cb, rel, g.simplex, ctx.scale);
        out.iterations += e.iterations;
        // EPA started from a simplex without the origin (GJK stopped Separated, tiny gap) ends on
        // a face the origin lies outside of: a negative "depth" whose witnesses are not closest
        // points (point_b - point_a was off signed_distance * normal by more than the gap) and
        // whose normal may be far off. Such a pair is separated: GJK's distance and closest
        // points answer, consistent by construction (point_b - point_a = distance * normal).
        const bool epa_penetrating = e.state == EpaState::Converged && e.depth > 0;
        if (g.state == GjkState::Separated && g.distance > 0 && !epa_penetrating &&
            (g.point_b - g.point_a).norm() > 0) {
            core_a = g.point_a;
            core_b = g.point_b;
            out.normal = (core_b - core_a).normalized();
            out.signed_distance = g.distance;
        } else if (e.state == EpaState::Converged) {
            core_a = e.point_a;
            core_b = e.point_b;
            out.normal = e.normal;
            out.signed_distance = -e.depth;
        } else {
            out.state = ContactState::Failed;
            return;
        }
        // Either direction runs through a gap or depth of rounding size (a face-to-face touching
        // pair got normals 70 degrees off its face normal): shiftedEpa() measures the contact
        // again with the cores overlapping well above rounding. Only an answer whose normal is
        // stable under the shift replaces this one (face contacts, not vertex-vertex).
        Shifted shifted;
        if (std::abs(out.signed_distance) <= kNormalRelative * ctx.scale &&
            shiftedEpa(ca, cb, rel, out.normal, ctx.scale, shifted, out.iterations)) {
            out.normal = shifted.normal;
            out.signed_distance = shifted.separation;
            core_a = shifted.core_a;
            core_b = shifted.core_b;
        }
        out.signed_distance -= radii;
    }
    out.point_a = core_a + ca.radius * out.normal;
    out.point_b = core_b - cb.radius * out.normal;
    const Real tol = kFeatureRelative * ctx.scale;
    out.feature_a = coreFeature(a, core_a, tol);
    out.feature_b = coreFeature(b, toB(rel, core_b), tol);
    out.state = ContactState::Touching;  // placeholder: classified by the caller
}

// ---- Box-box: SAT over 15 axes, manifold by clipping (A's frame). ----

// Sutherland-Hodgman (RTCD 8.3.4): keeps the part of polygon `in` with coord[axis] * sign <= limit.
int clipPolygon(const std::array<Vec3, 8>& in, int n, int axis, Real sign, Real limit,
                std::array<Vec3, 8>& out) {
    int m = 0;
    for (int i = 0; i < n; ++i) {
        const Vec3& p = in[static_cast<std::size_t>(i)];
        const Vec3& q = in[static_cast<std::size_t>((i + 1) % n)];
        const Real dp = sign * p[axis] - limit;
        const Real dq = sign * q[axis] - limit;
        if (dp <= 0 && m < 8) out[static_cast<std::size_t>(m++)] = p;
        if ((dp < 0 && dq > 0) || (dp > 0 && dq < 0)) {
            const Real t = dp / (dp - dq);
            Vec3 x = p + t * (q - p);
            x[axis] = sign * limit;  // exactly on the plane
            if (m < 8) out[static_cast<std::size_t>(m++)] = x;
        }
    }
    return m;
}

// Face contact: reference box R (half extents hr, its frame), reference face on axis k with
// outward sign s; incident box I (half extents hi) placed by i_in_r. Writes points of I inside
// the reference face's slab with their depths below the face (>= -tolerance), in R's frame.
int clipFaceContact(const Vec3& hr, int k, Real s, const Vec3& hi, const RelativePose& i_in_r,
                    Real tolerance, std::array<Vec3, 8>& points, std::array<Real, 8>& depths) {
    // Incident face: the face of I most anti-parallel to the reference normal.
    const Vec3 n_in_i = i_in_r.rotation.transpose() * (s * Vec3::Unit(k));
    int m = 0;
    n_in_i.cwiseAbs().maxCoeff(&m);
    const Real sm = -signOrPlus(n_in_i[m]);
    const int u = (m + 1) % 3;
    const int v = (m + 2) % 3;
    std::array<Vec3, 8> poly{};
    const std::array<Real, 4> su{-1, 1, 1, -1};
    const std::array<Real, 4> sv{-1, -1, 1, 1};
    for (int c = 0; c < 4; ++c) {
        Vec3 corner;
        corner[m] = sm * hi[m];
        corner[u] = su[static_cast<std::size_t>(c)] * hi[u];
        corner[v] = sv[static_cast<std::size_t>(c)] * hi[v];
        poly[static_cast<std::size_t>(c)] = i_in_r.rotation * corner + i_in_r.position;
    }
    int n = 4;
    std::array<Vec3, 8> tmp{};
    const int a1 = (k + 1) % 3;
    const int a2 = (k + 2) % 3;
    n = clipPolygon(poly, n, a1, 1, hr[a1], tmp);
    n = clipPolygon(tmp, n, a1, -1, hr[a1], poly);
    n = clipPolygon(poly, n, a2, 1, hr[a2], tmp);
    n = clipPolygon(tmp, n, a2, -1, hr[a2], poly);
    int kept = 0;
    for (int i = 0; i < n; ++i) {
        const Vec3& p = poly[static_cast<std::size_t>(i)];
        const Real depth = hr[k] - s * p[k];
        if (depth >= -tolerance) {
            points[static_cast<std::size_t>(kept)] = p;
            depths[static_cast<std::size_t>(kept)] = depth;
            ++kept;
        }
    }
    return kept;
}

// Keeps at most 4 of n points: the deepest, the farthest from it, the one spanning the largest
// triangle with those two, and the one adding the most area outside that triangle (Gregorius,
// "Robust Contact Creation for Physics Simulations", GDC 2015). Returns the chosen indices.
int reduceManifold(const Vec3* p, const Real* depth, int n, const Vec3& normal,
                   std::array<int, 4>& chosen) {
    if (n <= 4) {
        for (int i = 0; i < n; ++i) chosen[static_cast<std::size_t>(i)] = i;
        return n;
    }
    auto at = [&](int i) -> const Vec3& { return p[i]; };
    int i0 = 0;
    for (int i = 1; i < n; ++i) {
        if (depth[i] > depth[i0]) i0 = i;
    }
    int i1 = -1;
    Real best = -1;
    for (int i = 0; i < n; ++i) {
        const Real d = (at(i) - at(i0)).squaredNorm();
        if (i != i0 && d > best) {
            best = d;
            i1 = i;
        }
    }
    int i2 = -1;
    Real best_area = -1;
    Real orientation = 1;
    for (int i = 0; i < n; ++i) {
        if (i == i0 || i == i1) continue;
        const Real area = (at(i1) - at(i0)).cross(at(i) - at(i0)).dot(normal);
        if (std::abs(area) > best_area) {
            best_area = std::abs(area);
            i2 = i;
            orientation = signOrPlus(area);
        }
    }
    int i3 = -1;
    Real best_out = 0;
    const std::array<int, 3> tri{i0, i1, i2};
    for (int i = 0; i < n; ++i) {
        if (i == i0 || i == i1 || i == i2) continue;
        for (int e = 0; e < 3; ++e) {
            const Vec3& s = at(tri[static_cast<std::size_t>(e)]);
            const Vec3& t = at(tri[static_cast<std::size_t>((e + 1) % 3)]);
            // Negative signed area w.r.t. the triangle's orientation: outside edge e.
            const Real area = -orientation * (t - s).cross(at(i) - s).dot(normal);
            if (area > best_out) {
                best_out = area;
                i3 = i;
            }
        }
    }
    chosen = {i0, i1, i2, i3};
    return i3 < 0 ? 3 : 4;
}

// Returns false when the SAT proves a gap larger than the tolerance (GJK then measures it).
bool boxBox(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx, Local& out) {
    const Mat3& rot = rel.rotation;
    const Vec3& t = rel.position;
    const Vec3& ea = a.half_extents;
    const Vec3& eb = b.half_extents;
    // Best face axis and best edge axis: largest separation (least penetration).
    Real best_face = -std::numeric_limits<Real>::infinity();
    int face_kind = 0;  // 0: face of A, 1: face of B
    int face_axis = 0;
    Real best_edge = -std::numeric_limits<Real>::infinity();
    int edge_i = 0;
    int edge_j = 0;
    Vec3 edge_axis = Vec3::Zero();
    for (int i = 0; i < 3; ++i) {
        const Real sep = std::abs(t[i]) - ea[i] - eb.dot(rot.row(i).transpose().cwiseAbs());
        if (sep > best_face) {
            best_face = sep;
            face_kind = 0;
            face_axis = i;
        }
    }
    for (int j = 0; j < 3; ++j) {
        const Vec3 axis = rot.col(j);
        const Real sep = std::abs(t.dot(axis)) - ea.dot(axis.cwiseAbs()) - eb[j];
        if (sep > best_face) {
            best_face = sep;
            face_kind = 1;
            face_axis = j;
        }
    }
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            const Vec3 axis = Vec3::Unit(i).cross(rot.col(j));
            const Real len2 = axis.squaredNorm();
            if (!(len2 >= kSatAxisMin)) continue;
            const Real len = std::sqrt(len2);
            const Vec3 unit = axis / len;
            const Real sep = std::abs(t.dot(unit)) - ea.dot(unit.cwiseAbs()) -
                             eb.dot((rot.transpose() * unit).cwiseAbs());
            if (sep > best_edge) {
                best_edge = sep;
                edge_i = i;
                edge_j = j;
                edge_axis = unit;
            }
        }
    }
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
        return true;
    }

    std::array<Vec3, 8> points{};
    std::array<Real, 8> depths{};
    int count = 0;
    Vec3 n;
    if (face_kind == 0) {
        const Real s = signOrPlus(t[face_axis]);
        n = s * Vec3::Unit(face_axis);
        count = clipFaceContact(ea, face_axis, s, eb, rel, ctx.tolerance, points, depths);
    } else {
        const Vec3 axis = rot.col(face_axis);
        const Real s = signOrPlus(t.dot(axis));
        n = s * axis;
        // B is the reference: work in B's frame with A as the incident box.
        RelativePose a_in_b;
        a_in_b.rotation = rot.transpose();
        a_in_b.position = -(rot.transpose() * t);
        count = clipFaceContact(eb, face_axis, -s, ea, a_in_b, ctx.tolerance, points, depths);
        for (int i = 0; i < count; ++i) {
            points[static_cast<std::size_t>(i)] = rot * points[static_cast<std::size_t>(i)] + t;
        }
    }
    // Points deeper than the contact lie beyond the far side of a thin reference box.
    const Real max_depth = std::max(Real(0), -best) + kFeatureRelative * ctx.scale;
    int within = 0;
    for (int i = 0; i < count; ++i) {
        if (depths[static_cast<std::size_t>(i)] <= max_depth) {
            points[static_cast<std::size_t>(within)] = points[static_cast<std::size_t>(i)];
            depths[static_cast<std::size_t>(within)] = depths[static_cast<std::size_t>(i)];
            ++within;
        }
    }
    count = within;
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
    return true;
}

// ---- Face contacts of polytopes (box or hull) other than box-box: clipped manifold. ----

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
        const Vec3& q = in[static_cast<std::size_t>((i + 1) % n)];
        const Real dp = m.dot(p) - c;
        const Real dq = m.dot(q) - c;
        if (dp <= 0 && k < 2 * kMaxPolygon) out[static_cast<std::size_t>(k++)] = p;
        if (((dp < 0 && dq > 0) || (dp > 0 && dq < 0)) && k < 2 * kMaxPolygon) {
            out[static_cast<std::size_t>(k++)] = p + (dp / (dp - dq)) * (q - p);
        }
    }
    return k;
}

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

// ---- Canonical dispatch ----

Local contactLocal(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx) {
    Local out;
    out.state = ContactState::Touching;  // classified later unless Failed
    const ShapeType ta = a.type;
    const ShapeType tb = b.type;
    if (ta == ShapeType::Sphere && tb == ShapeType::Sphere) {
        sphereSphere(a, b, rel, ctx, out);
    } else if (ta == ShapeType::Sphere && tb == ShapeType::Box) {
        sphereBox(a, b, rel, ctx, out);
    } else if (ta == ShapeType::Sphere && tb == ShapeType::Capsule) {
        sphereCapsule(a, b, rel, ctx, out);
    } else if (ta == ShapeType::Capsule && tb == ShapeType::Capsule) {
        capsuleCapsule(a, b, rel, ctx, out);
    } else if (ta == ShapeType::Box && tb == ShapeType::Box) {
        if (!boxBox(a, b, rel, ctx, out)) {
            out = Local{};
            generic(a, b, rel, ctx, out);
        }
    } else {
        generic(a, b, rel, ctx, out);
    }
    return out;
}

}  // namespace

ContactOutput contact(const Shape& a_in, const Pose& pose_a_in, const Shape& b_in,
                      const Pose& pose_b_in) {
    ContactOutput failed;
    if (!isFinite(a_in, pose_a_in) || !isFinite(b_in, pose_b_in)) return failed;
    // A mesh is its convex hull here.
    Shape a_hull;
    Shape b_hull;
    const Shape* a = &a_in;
    const Shape* b = &b_in;
    if (a_in.type == ShapeType::Mesh) {
        a_hull = Shape::convexHull(a_in.hull);
        a = &a_hull;
    }
    if (b_in.type == ShapeType::Mesh) {
        b_hull = Shape::convexHull(b_in.hull);
        b = &b_hull;
    }
    const bool swap = canonicalLess(*b, pose_b_in, *a, pose_a_in);
    const Shape& first = swap ? *b : *a;
    const Shape& second = swap ? *a : *b;
    const Pose& pose_first = swap ? pose_b_in : pose_a_in;
    const Pose& pose_second = swap ? pose_a_in : pose_b_in;

    Ctx ctx;
    ctx.scale = std::max(boundingRadius(first), boundingRadius(second));
    ctx.tolerance = kTouchRelativeTolerance * ctx.scale;
    const RelativePose rel = relativePose(pose_first, pose_second);
    Local local = contactLocal(first, second, rel, ctx);

    // The touching convention; near its thresholds collide() decides (see the file header).
    const bool convex = a_in.isConvex() && b_in.isConvex();
    if (local.state != ContactState::Failed) {
        local.state = classifySignedDistance(local.signed_distance, ctx.tolerance).state;
    }
    const Real band = kReconcileBand * ctx.scale;
    if (convex && (local.state == ContactState::Failed ||
                   std::abs(local.signed_distance) <= ctx.tolerance + band)) {
        const CollideOutput c = collide(first, pose_first, second, pose_second);
        if (local.state != ContactState::Failed) {
            switch (c.state) {
                case ContactState::Separated:
                    local.signed_distance = std::max(local.signed_distance, c.distance);
                    break;
                case ContactState::Touching:
                    local.signed_distance =
                        std::clamp(local.signed_distance, -ctx.tolerance, ctx.tolerance);
                    break;
                case ContactState::Penetrating:
                    if (!(local.signed_distance < -ctx.tolerance)) {
                        local.signed_distance =
                            std::nextafter(-ctx.tolerance, -std::numeric_limits<Real>::infinity());
                    }
                    break;
                case ContactState::Failed:
                    break;
            }
            local.state = c.state;
        }
    }
    // The output never carries NaN or a non-unit normal: anything else is Failed.
    if (local.state == ContactState::Failed || !std::isfinite(local.signed_distance) ||
        !local.normal.allFinite() || !(std::abs(local.normal.squaredNorm() - 1) < Real(1e-6)) ||
        !local.point_a.allFinite() || !local.point_b.allFinite()) {
        failed.iterations = local.iterations;
        return failed;
    }
    if (local.state == ContactState::Separated) {
        local.manifold_size = 0;
    } else if (local.manifold_size == 0) {
        const bool polytopes =
            (first.type == ShapeType::Box || first.type == ShapeType::ConvexHull) &&
            (second.type == ShapeType::Box || second.type == ShapeType::ConvexHull);
        if (!polytopes || !polytopeManifold(first, second, rel, ctx, local)) {
            setSingleManifold(local);
        }
    }

    // To world, once; then mirror if the canonical order swapped A and B.
    ContactOutput out = local;
    const Mat3 rot = pose_first.rotation();
    out.normal = rot * local.normal;
    out.point_a = pose_first.apply(local.point_a);
    out.point_b = pose_first.apply(local.point_b);
    for (int i = 0; i < local.manifold_size; ++i) {
        const auto k = static_cast<std::size_t>(i);
        out.manifold[k].point_a = pose_first.apply(local.manifold[k].point_a);
        out.manifold[k].point_b = pose_first.apply(local.manifold[k].point_b);
    }
    if (swap) {
        out.normal = -out.normal;
        std::swap(out.point_a, out.point_b);
        std::swap(out.feature_a, out.feature_b);
        for (int i = 0; i < out.manifold_size; ++i) {
            auto& m = out.manifold[static_cast<std::size_t>(i)];
            std::swap(m.point_a, m.point_b);
        }
    }
    return out;
}

}  // namespace collision
