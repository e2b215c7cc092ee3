// collision/src/narrowphase/gjk.cpp -- GJK distance (van den Bergen 1999, "A Fast and Robust GJK
// Implementation for Collision Detection of Convex Objects"; RTCD 9.5), one loop for both vertex
// types: w = a - b alone, or with a and b kept so the closest point's barycentric weights give
// witness points (§3); and the state decision of a convex pair from a GJK run (decideConvexCores),
// with the bounded EPA (epa.h) when the cores overlap.
// Invariants: |v| decreases strictly every GJK iteration or GJK stops; it runs at most
// kGjkMaxIterations times and reports Failed rather than loop; no division by a quantity that
// was not checked against a scale-relative epsilon, so finite input never produces NaN.
#include "narrowphase/gjk.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <variant>

#include "collision/assert.h"
#include "geometry/closest_points.h"
#include "narrowphase/epa.h"

namespace collision {

namespace {

// Below this multiple of kEpsilon * (size of the simplex) |v| is rounding noise.
constexpr Real kOverlapRelative = Real(32) * kEpsilon;

Real signOrPlus(Real x) { return x < 0 ? Real(-1) : Real(1); }

template <class Vertex>
using Simplex = GjkSimplex<Vertex>;

// Replaces the simplex by the sub-simplex supporting its closest point to the origin (the
// vertices of positive weight), sets `weight` to their weights, and returns that point
// (closest_points.h). Sets `enclosed`, leaving the simplex as it is, when a tetrahedron contains
// the origin.
template <class Vertex>
Vec3 closestOnSimplex(Simplex<Vertex>& s, std::array<Real, 4>& weight, bool& enclosed) {
    enclosed = false;
    weight = {0, 0, 0, 0};
    Vec3 p = pointOf(s.v[0]);
    if (s.n == 1) {
        weight[0] = 1;
    } else if (s.n == 2) {
        p = closestOnSegment(pointOf(s.v[0]), pointOf(s.v[1]), weight[0], weight[1]);
    } else if (s.n == 3) {
        std::array<Real, 3> w3{};
        p = closestOnTriangle(pointOf(s.v[0]), pointOf(s.v[1]), pointOf(s.v[2]), w3);
        weight = {w3[0], w3[1], w3[2], 0};
    } else {
        p = closestOnTetrahedron({pointOf(s.v[0]), pointOf(s.v[1]), pointOf(s.v[2]),
                                  pointOf(s.v[3])},
                                 weight, enclosed);
        if (enclosed) return p;
    }
    Simplex<Vertex> reduced;
    std::array<Real, 4> reduced_weight{0, 0, 0, 0};
    for (int i = 0; i < s.n; ++i) {
        if (weight[i] > 0) {
            reduced_weight[reduced.n] = weight[i];
            reduced.v[reduced.n++] = s.v[i];
        }
    }
    if (reduced.n == 0) {
        reduced.v[reduced.n++] = s.v[0];
        reduced_weight[0] = 1;
    }
    s = reduced;
    weight = reduced_weight;
    return p;
}

template <class Vertex>
Real maxNorm(const Simplex<Vertex>& s) {
    Real m = 0;
    for (int i = 0; i < s.n; ++i) m = std::max(m, pointOf(s.v[i]).norm());
    return m;
}

// The result of the one GJK loop below: with witness points it is GjkWitnessOutput itself (the
// weights of `closest` applied to the simplex's support points, updated whenever |v|
// decreases); without, the summary and the simplex of w's.
struct GjkDistanceRun : GjkSummary {
    Simplex<Vec3> simplex;
};
// (v.w, |v|^2) of each iteration's separating plane; left uninitialised (only the logged
// entries are read).
struct PlaneLog {
    std::array<Real, kGjkMaxIterations> vw;
    std::array<Real, kGjkMaxIterations> vv;
};

template <class Vertex>
using GjkRun = std::conditional_t<std::is_same_v<Vertex, Vec3>, GjkDistanceRun, GjkWitnessOutput>;

// GJK distance (van den Bergen 1999; RTCD 9.5). Invariant: |v| decreases strictly every
// iteration or the loop stops; at most kGjkMaxIterations iterations, then Failed.
template <class Vertex>
GjkRun<Vertex> runGjk(const ConvexCore& a, const ConvexCore& b, const RelativePose& b_in_a,
                      Real scale) {
    constexpr bool kWitness = !std::is_same_v<Vertex, Vec3>;
    const MinkowskiDifference cso{a, b, b_in_a};
    GjkRun<Vertex> out;
    out.lower_bound = -std::numeric_limits<Real>::infinity();
    const Real tiny = std::max(kOverlapRelative * scale, std::numeric_limits<Real>::min());
    Simplex<Vertex>& s = out.simplex;
    // Any point of A - B starts the search; -position points from B's origin towards A's.
    s.v[0] = cso.supportVertex<Vertex>(-b_in_a.position);
    s.n = 1;
    Vec3 v = pointOf(s.v[0]);
    if constexpr (kWitness) {
        out.point_a = s.v[0].a;
        out.point_b = s.v[0].b;
    }
    // The separating planes' lower bound: gjkDistance keeps it as it goes; gjkWitness logs the
    // planes and evaluates the same expression in the same order only when it is read (Failed,
    // decideConvexCores), so both report the same value without a square root per iteration.
    std::conditional_t<kWitness, PlaneLog, std::monostate> planes;
    int plane_count = 0;
    auto finish = [&](GjkState state, Real distance) {
        if constexpr (kWitness) {
            if (state == GjkState::Failed) {
                for (int i = 0; i < plane_count; ++i) {
                    out.lower_bound = std::max(out.lower_bound, planes.vw[i] / std::sqrt(planes.vv[i]));
                }
            }
        }
        out.state = state;
        out.distance = distance;
        out.closest = v;
        return out;
    };

    for (int iter = 0; iter < kGjkMaxIterations; ++iter) {
        out.iterations = iter + 1;
        const Real vv = v.squaredNorm();
        const Real noise = std::max(kOverlapRelative * maxNorm(s), tiny);
        if (vv <= noise * noise) {
            out.lower_bound = std::max(out.lower_bound, Real(0));
            return finish(GjkState::Overlapping, 0);
        }
        const Vertex w = cso.supportVertex<Vertex>(-v);
        const Real vw = v.dot(pointOf(w));
        // Every point x of A - B has v.x >= v.w, so distance >= v.w / |v| (a separating plane);
        // decideConvexCores uses it when the iteration cap is hit.
        if constexpr (kWitness) {
            planes.vw[plane_count] = vw;
            planes.vv[plane_count] = vv;
            ++plane_count;
        } else {
            out.lower_bound = std::max(out.lower_bound, vw / std::sqrt(vv));
        }
        // van den Bergen 1999 §4: |v|^2 - v.w bounds |v|^2 - |v| dist(origin, A - B).
        if (vv - vw <= kGjkRelativeTolerance * vv) {
            return finish(GjkState::Separated, std::sqrt(vv));
        }
        const Real dup = kDuplicateRelative * std::max(pointOf(w).norm(), maxNorm(s));
        for (int i = 0; i < s.n; ++i) {
            if ((pointOf(s.v[i]) - pointOf(w)).squaredNorm() <= dup * dup) {
                // No new support point: |v| is as good as rounding allows.
                return finish(GjkState::Separated, std::sqrt(vv));
            }
        }
        const Simplex<Vertex> before = s;
        s.v[s.n++] = w;
        std::array<Real, 4> weight{};
        bool enclosed = false;
        const Vec3 v_next = closestOnSimplex(s, weight, enclosed);
        if (enclosed) {
            out.lower_bound = std::max(out.lower_bound, Real(0));
            return finish(GjkState::Overlapping, 0);
        }
        if (!(v_next.squaredNorm() < vv)) {
            // |v| must decrease strictly (van den Bergen 1999 §4); rounding stalled it.
            s = before;
            return finish(GjkState::Separated, std::sqrt(vv));
        }
        v = v_next;
        if constexpr (kWitness) {
            out.point_a.setZero();
            out.point_b.setZero();
            for (int i = 0; i < s.n; ++i) {
                out.point_a += weight[i] * s.v[i].a;
                out.point_b += weight[i] * s.v[i].b;
            }
        }
    }
    return finish(GjkState::Failed, v.norm());
}

}  // namespace

ConvexCore ConvexCore::fromShape(const Shape& shape) {
    ConvexCore core;
    switch (shape.type) {
        case ShapeType::Sphere:
            core.kind = Kind::Point;
            core.radius = shape.radius;
            break;
        case ShapeType::Capsule:
            core.kind = Kind::Segment;
            core.v[0] = Vec3(0, -shape.half_height, 0);
            core.v[1] = Vec3(0, shape.half_height, 0);
            core.radius = shape.radius;
            break;
        case ShapeType::Box:
            core.kind = Kind::Box;
            core.half_extents = shape.half_extents;
            break;
        case ShapeType::ConvexHull:
        case ShapeType::Mesh:
            CDLAB_ASSERT(shape.hull && !shape.hull->vertices.empty(), "hull needs vertices");
            core.kind = Kind::Points;
            core.points = shape.hull->vertices.data();
            core.point_count = static_cast<std::int32_t>(shape.hull->vertices.size());
            break;
    }
    return core;
}

ConvexCore ConvexCore::triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
    ConvexCore core;
    core.kind = Kind::Triangle;
    core.v = {a, b, c};
    return core;
}

Vec3 ConvexCore::support(const Vec3& dir) const {
    switch (kind) {
        case Kind::Point:
            return v[0];
        case Kind::Segment:
            return v[0].dot(dir) > v[1].dot(dir) ? v[0] : v[1];
        case Kind::Triangle: {
            const Real d0 = v[0].dot(dir);
            const Real d1 = v[1].dot(dir);
            const Real d2 = v[2].dot(dir);
            if (d0 >= d1 && d0 >= d2) return v[0];
            return d1 >= d2 ? v[1] : v[2];
        }
        case Kind::Box:
            return Vec3(signOrPlus(dir.x()) * half_extents.x(),
                        signOrPlus(dir.y()) * half_extents.y(),
                        signOrPlus(dir.z()) * half_extents.z());
        case Kind::Points: {
            std::int32_t best = 0;
            Real best_dot = points[0].dot(dir);
            for (std::int32_t i = 1; i < point_count; ++i) {
                const Real d = points[i].dot(dir);
                if (d > best_dot) {
                    best_dot = d;
                    best = i;
                }
            }
            return points[best];
        }
    }
    return Vec3::Zero();
}

Real ConvexCore::boundingRadius() const {
    Real r = 0;
    switch (kind) {
        case Kind::Point:
            r = v[0].norm();
            break;
        case Kind::Segment:
            r = std::max(v[0].norm(), v[1].norm());
            break;
        case Kind::Triangle:
            r = std::max({v[0].norm(), v[1].norm(), v[2].norm()});
            break;
        case Kind::Box:
            r = half_extents.norm();
            break;
        case Kind::Points:
            for (std::int32_t i = 0; i < point_count; ++i) r = std::max(r, points[i].norm());
            break;
    }
    return r + radius;
}

GjkOutput gjkDistance(const ConvexCore& a, const ConvexCore& b, const RelativePose& b_in_a,
                      Real scale) {
    const GjkRun<Vec3> run = runGjk<Vec3>(a, b, b_in_a, scale);
    GjkOutput out;
    static_cast<GjkSummary&>(out) = run;
    out.simplex_count = run.simplex.n;
    std::copy_n(run.simplex.v.begin(), run.simplex.n, out.simplex.begin());
    return out;
}

GjkWitnessOutput gjkWitness(const ConvexCore& a, const ConvexCore& b, const RelativePose& b_in_a,
                            Real scale) {
    return runGjk<SupportVertex>(a, b, b_in_a, scale);
}

CollideOutput classifySignedDistance(Real signed_distance, Real tolerance) {
    CollideOutput out;
    if (signed_distance > tolerance) {
        out.state = ContactState::Separated;
        out.distance = signed_distance;
    } else if (signed_distance >= -tolerance) {
        out.state = ContactState::Touching;
    } else {
        out.state = ContactState::Penetrating;
    }
    return out;
}

CollideOutput decideConvexCores(const GjkSummary& g, const Vec3* simplex, int simplex_count,
                                const MinkowskiDifference& cso, Real radii, Real tolerance,
                                Real scale, Real start_closest) {
    CollideOutput out;
    switch (g.state) {
        case GjkState::Separated:
            // Inflating both cores by their radii shifts the signed distance by the radii.
            out = classifySignedDistance(g.distance - radii, tolerance);
            break;
        case GjkState::Overlapping:
            if (radii > tolerance) {
                out.state = ContactState::Penetrating;  // depth >= radii
            } else if (simplex_count == 4 && start_closest > tolerance - radii) {
                // The bounded EPA's first iteration on these very faces decides so.
                out.state = ContactState::Penetrating;
                out.iterations += 1;
            } else {
                GjkSimplex<Vec3> start;
                start.n = simplex_count;
                for (int i = 0; i < simplex_count; ++i) start.v[i] = simplex[i];
                std::int32_t epa_iterations = 0;
                out.state = epaDecide(cso, start, tolerance - radii, scale, epa_iterations);
                out.iterations += epa_iterations;
            }
            break;
        case GjkState::Failed:
            // The bounds may still decide: lower <= core distance <= upper.
            if (g.lower_bound - radii > tolerance) {
                out.state = ContactState::Separated;
                out.distance = g.distance - radii;
            } else if (g.lower_bound - radii >= -tolerance && g.distance - radii <= tolerance) {
                out.state = ContactState::Touching;
            } else {
                out.state = ContactState::Failed;
            }
            break;
    }
    out.iterations += g.iterations;
    return out;
}

CollideOutput collideConvexCores(const ConvexCore& a, const ConvexCore& b,
                                 const RelativePose& b_in_a, Real tolerance, Real scale) {
    const GjkOutput g = gjkDistance(a, b, b_in_a, scale);
    return decideConvexCores(g, g.simplex.data(), g.simplex_count, MinkowskiDifference{a, b, b_in_a},
                             a.radius + b.radius, tolerance, scale);
}

}  // namespace collision
