// collision/src/narrowphase/epa.cpp -- the expanding polytope algorithm (van den Bergen 2001 §4;
// RTCD 9.5 for the simplex sub-steps), from GJK's final simplex (gjk.h), with two stopping rules
// on one polytope (epa_polytope.h): the full depth with witnesses (epaPenetration, contact()) and
// the bounded decision "deeper than a threshold?" (epaDecide, collide()).
// Invariants: the loop is capped (kEpaMaxIterations) and reports Failed; every division is
// guarded by a scale-relative epsilon, so finite input never yields NaN; faces and horizon edges
// are visited in index order, so the output is deterministic.
#include "narrowphase/epa.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "geometry/closest_points.h"
#include "narrowphase/epa_polytope.h"

namespace collision {

namespace {

// ---- EPA polytope ----

using Polytope = EpaPolytope<SupportVertex, kEpaMaxIterations + 4>;
using Face = Polytope::Face;

// Writes the output for face f: the origin's projection n * dist expressed in the face's
// vertices, and the same weights applied to their support points.
void faceOutput(const Polytope& poly, const Face& f, EpaOutput& out) {
    const SupportVertex& p = poly.vert[static_cast<std::size_t>(f.v[0])];
    const SupportVertex& q = poly.vert[static_cast<std::size_t>(f.v[1])];
    const SupportVertex& r = poly.vert[static_cast<std::size_t>(f.v[2])];
    std::array<Real, 3> w{};
    closestOnTriangle(p.w, q.w, r.w, w);
    out.normal = f.normal;
    out.depth = f.dist;
    out.point_a = w[0] * p.a + w[1] * q.a + w[2] * r.a;
    out.point_b = w[0] * p.b + w[1] * q.b + w[2] * r.b;
}

// Coplanar faces (a split face of the obstacle) share the distance of the face nearest the origin
// (`closest`, up to `tol`); the origin's projection lies in the one whose own closest point to
// the origin is nearest.
Face faceHoldingProjection(const Polytope& poly, const Face& closest, Real tol) {
    Face chosen = closest;
    Real chosen2 = std::numeric_limits<Real>::infinity();
    for (int f = 0; f < poly.face_count; ++f) {
        const Face& face = poly.faces[static_cast<std::size_t>(f)];
        if (!face.valid || face.normal.isZero() || face.dist > closest.dist + tol) continue;
        std::array<Real, 3> wt{};
        const Real d2 = closestOnTriangle(poly.point(face.v[0]), poly.point(face.v[1]),
                                          poly.point(face.v[2]), wt)
                            .squaredNorm();
        if (d2 < chosen2) {
            chosen2 = d2;
            chosen = face;
        }
    }
    return chosen;
}

// Grows GJK's simplex (in `poly`, 1 to 4 vertices) to a tetrahedron by support points along
// directions off its span. False when the answer is already in `out`: a flat obstacle (the
// best probe's plane, Converged) or the cap (Failed).
bool blowUpToTetrahedron(const MinkowskiDifference& cso, Polytope& poly, EpaOutput& out) {
    // Every probed direction n gives an upper bound h(n) on the depth; the best one answers when
    // the obstacle is flat (zero volume) and the polytope cannot grow to a tetrahedron.
    Real best_h = std::numeric_limits<Real>::infinity();
    auto probe = [&](const Vec3& dir) {
        const SupportVertex s = cso.supportVertex<SupportVertex>(dir);
        const Real h = dir.dot(s.w);
        if (h < best_h) {
            best_h = h;
            out.normal = dir;
            out.depth = std::max(h, Real(0));
            out.point_a = s.a;
            out.point_b = s.b;
        }
        return s;
    };

    while (poly.vertex_count < 4) {
        if (++out.iterations > kEpaMaxIterations) return false;  // Failed
        std::array<Vec3, 6> dirs{};
        const int dir_count = poly.blowUpDirections(dirs);
        if (dir_count == 0) {
            --poly.vertex_count;  // a duplicate or collinear last vertex: drop it, probe again
            continue;
        }
        bool grown = false;
        for (int k = 0; k < dir_count && !grown; ++k) {
            const SupportVertex s = probe(dirs[static_cast<std::size_t>(k)]);
            if (poly.offSpan(dirs[static_cast<std::size_t>(k)], s.w) > poly.eps) {
                poly.vert[static_cast<std::size_t>(poly.vertex_count++)] = s;
                grown = true;
            }
        }
        if (!grown) {
            // Flat obstacle: the best probe's plane is the answer (depth 0 up to rounding).
            out.state = std::isfinite(best_h) ? EpaState::Converged : EpaState::Failed;
            return false;
        }
    }
    return true;

}

}  // namespace

EpaOutput epaPenetration(const ConvexCore& a, const ConvexCore& b, const RelativePose& b_in_a,
                         const WitnessSimplex& start, Real scale) {
    const MinkowskiDifference cso{a, b, b_in_a};
    EpaOutput out;
    Polytope poly;
    poly.eps = std::max(Real(64) * kEpsilon * scale, std::numeric_limits<Real>::min());
    const Real tol = std::max(kEpaRelativeTolerance * scale, std::numeric_limits<Real>::min());
    for (int i = 0; i < start.n; ++i)
        poly.vert[static_cast<std::size_t>(poly.vertex_count++)] =
            start.v[static_cast<std::size_t>(i)];

    if (!blowUpToTetrahedron(cso, poly, out)) return out;
    const bool started_as_tetrahedron = out.iterations == 0;
    poly.closeTetrahedron();
    for (int iter = 0; iter < kEpaMaxIterations; ++iter) {
        ++out.iterations;
        const int best = poly.closestFace();
        if (iter == 0 && started_as_tetrahedron && best >= 0) {
            out.start_closest = poly.faces[static_cast<std::size_t>(best)].dist;
        }
        if (best < 0) {
            out.state = EpaState::Failed;
            return out;
        }
        const Face closest = poly.faces[static_cast<std::size_t>(best)];
        const SupportVertex w = cso.supportVertex<SupportVertex>(closest.normal);
        const Real h = closest.normal.dot(w.w);
        // Lower bound closest.dist <= depth <= h (van den Bergen 2001 §4).
        if (h - closest.dist <= tol || poly.holdsPoint(w.w, scale)) {
            faceOutput(poly, faceHoldingProjection(poly, closest, tol), out);
            out.state = EpaState::Converged;
            return out;
        }
        if (!poly.expand(w)) break;
    }
    out.state = EpaState::Failed;
    return out;
}

// ---- The bounded decision: does the penetration depth exceed `threshold`? ----

namespace {

using DecidePolytope = EpaPolytope<Vec3, kGjkMaxIterations + 4>;

}  // namespace

ContactState epaDecide(const MinkowskiDifference& cso, const GjkSimplex<Vec3>& start,
                       Real threshold, Real scale, std::int32_t& iterations) {
    DecidePolytope poly;
    poly.eps = std::max(Real(64) * kEpsilon * scale, std::numeric_limits<Real>::min());
    for (int i = 0; i < start.n; ++i) poly.vert[poly.vertex_count++] = start.v[i];

    // Direction probes: any direction n with support h(n) <= threshold proves depth <= threshold.
    auto probe = [&](const Vec3& dir, Vec3& w_out) {
        w_out = cso.support(dir);
        return dir.dot(w_out) <= threshold;
    };

    // Blow a lower-dimensional simplex up to a tetrahedron (the CSO is 3-D unless it is flat, and
    // a flat CSO has penetration depth zero).
    while (poly.vertex_count < 4) {
        std::array<Vec3, 6> dirs{};
        const int dir_count = poly.blowUpDirections(dirs);
        if (dir_count == 0) {
            if (poly.vertex_count == 3) return ContactState::Touching;  // collinear: flat CSO
            --poly.vertex_count;  // a duplicate second vertex: probe from the first
            continue;
        }
        bool grown = false;
        for (int k = 0; k < dir_count && !grown; ++k) {
            Vec3 w;
            if (probe(dirs[k], w)) return ContactState::Touching;
            if (poly.offSpan(dirs[k], w) > poly.eps) {
                poly.vert[poly.vertex_count++] = w;
                grown = true;
            }
        }
        if (!grown) return ContactState::Touching;  // flat CSO: zero depth
    }

    poly.closeTetrahedron();
    for (int iter = 0; iter < kGjkMaxIterations; ++iter) {
        ++iterations;
        const int best = poly.closestFace();
        if (best < 0) return ContactState::Failed;
        const DecidePolytope::Face closest = poly.faces[best];
        // The origin lies inside the polytope (inside the CSO), so depth >= closest plane
        // distance; and depth <= h(n) for every probed n (van den Bergen 2001 §4).
        if (closest.dist > threshold) return ContactState::Penetrating;
        Vec3 w;
        if (probe(closest.normal, w)) return ContactState::Touching;
        const Real h = closest.normal.dot(w);
        if (h - closest.dist <= poly.eps) {
            // Converged at depth ~ threshold: the bounds no longer separate; call it touching.
            return ContactState::Touching;
        }
        // A support point already in the polytope cannot grow it: the depth is closest.dist up
        // to rounding (<= threshold here). Without this check exactly touching boxes re-added
        // the same vertex until the cap and came out Failed.
        if (poly.holdsPoint(w, scale)) return ContactState::Touching;
        if (!poly.expand(w)) return ContactState::Failed;
    }
    return ContactState::Failed;
}


}  // namespace collision
