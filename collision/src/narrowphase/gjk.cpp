// collision/src/narrowphase/gjk.cpp -- GJK distance (van den Bergen 1999, "A Fast and Robust GJK
// Implementation for Collision Detection of Convex Objects"; RTCD 9.5) and the bounded EPA
// decision (van den Bergen 2001 "Proximity Queries and Penetration Depth Computation on 3D Game
// Objects") used when the cores overlap.
// Invariants: |v| decreases strictly every GJK iteration or GJK stops; both loops run at most
// kGjkMaxIterations times and report Failed rather than loop; no division by a quantity that
// was not checked against a scale-relative epsilon, so finite input never produces NaN.
#include "narrowphase/gjk.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "collision/assert.h"

namespace collision {

namespace {

// Below these multiples of kEpsilon * (size of the simplex) a length is rounding noise.
constexpr Real kOverlapRelative = Real(32) * kEpsilon;
constexpr Real kDuplicateRelative = Real(8) * kEpsilon;
constexpr Real kDegenerateRelative = Real(1e3) * kEpsilon;

Real signOrPlus(Real x) { return x < 0 ? Real(-1) : Real(1); }

// Support mapping of the configuration-space obstacle A - B, in A's frame.
struct MinkowskiDifference {
    const ConvexCore& a;
    const ConvexCore& b;
    const RelativePose& b_in_a;

    Vec3 support(const Vec3& dir) const {
        const Vec3 dir_in_b = b_in_a.rotation.transpose() * (-dir);
        const Vec3 on_b = b_in_a.rotation * b.support(dir_in_b) + b_in_a.position;
        return a.support(dir) - on_b;
    }
};

// Closest point to the origin on segment ab, RTCD 5.1.2; weights of a and b.
Vec3 closestOnSegment(const Vec3& a, const Vec3& b, Real& wa, Real& wb) {
    const Vec3 ab = b - a;
    const Real len2 = ab.squaredNorm();
    const Real t_num = -a.dot(ab);
    if (t_num <= 0 || !(len2 > 0)) {
        wa = 1;
        wb = 0;
        return a;
    }
    if (t_num >= len2) {
        wa = 0;
        wb = 1;
        return b;
    }
    const Real t = t_num / len2;
    wa = 1 - t;
    wb = t;
    return a + t * ab;
}

// Closest point to the origin on triangle abc, RTCD 5.1.5 (Voronoi regions); barycentric weights.
Vec3 closestOnTriangle(const Vec3& a, const Vec3& b, const Vec3& c, std::array<Real, 3>& w) {
    const Vec3 ab = b - a;
    const Vec3 ac = c - a;
    const Real d1 = -ab.dot(a);
    const Real d2 = -ac.dot(a);
    if (d1 <= 0 && d2 <= 0) {
        w = {1, 0, 0};
        return a;
    }
    const Real d3 = -ab.dot(b);
    const Real d4 = -ac.dot(b);
    if (d3 >= 0 && d4 <= d3) {
        w = {0, 1, 0};
        return b;
    }
    const Real vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const Real t = d1 / (d1 - d3);  // d1 >= 0 >= d3 and not both zero here
        w = {1 - t, t, 0};
        return a + t * ab;
    }
    const Real d5 = -ab.dot(c);
    const Real d6 = -ac.dot(c);
    if (d6 >= 0 && d5 <= d6) {
        w = {0, 0, 1};
        return c;
    }
    const Real vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const Real t = d2 / (d2 - d6);
        w = {1 - t, 0, t};
        return a + t * ac;
    }
    const Real va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const Real t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        w = {0, 1 - t, t};
        return b + t * (c - b);
    }
    const Real denom = va + vb + vc;
    const Real area_scale = ab.squaredNorm() * ac.squaredNorm();
    if (!(denom > kDegenerateRelative * area_scale)) {
        // Sliver triangle: the regions above are unreliable; take the best edge.
        std::array<Real, 3> best{1, 0, 0};
        Vec3 best_p = a;
        Real wa = 0;
        Real wb = 0;
        const Vec3 p_ab = closestOnSegment(a, b, wa, wb);
        best = {wa, wb, 0};
        best_p = p_ab;
        const Vec3 p_bc = closestOnSegment(b, c, wa, wb);
        if (p_bc.squaredNorm() < best_p.squaredNorm()) {
            best = {0, wa, wb};
            best_p = p_bc;
        }
        const Vec3 p_ca = closestOnSegment(c, a, wa, wb);
        if (p_ca.squaredNorm() < best_p.squaredNorm()) {
            best = {wb, 0, wa};
            best_p = p_ca;
        }
        w = best;
        return best_p;
    }
    // Face region: the origin's projection onto the plane, x = n (n.a) / |n|^2, with its
    // signed-area coordinates as weights. For slivers far from the origin this is much more
    // accurate than a + v ab + t ac, whose error grows like |a|^2 / area and can stall GJK at a
    // wrong distance (a 3e-5-thin box touching a 5-unit box came out 6e-6 apart).
    const Vec3 n = ab.cross(ac);
    const Real nn = n.squaredNorm();
    if (nn > 0) {
        const Vec3 x = n * (n.dot(a) / nn);
        const Real wa = n.dot((b - x).cross(c - x)) / nn;
        const Real wb = n.dot((c - x).cross(a - x)) / nn;
        w = {wa, wb, 1 - wa - wb};
        return x;
    }
    const Real v = vb / denom;
    const Real t = vc / denom;
    w = {1 - v - t, v, t};
    return a + ab * v + ac * t;
}

struct Simplex {
    std::array<Vec3, 4> w{};
    int n = 0;
};

// Replaces the simplex by the sub-simplex supporting its closest point to the origin and returns
// that point. Sets `enclosed` when a tetrahedron contains the origin (RTCD 5.1.6).
Vec3 closestOnSimplex(Simplex& s, bool& enclosed) {
    enclosed = false;
    std::array<Real, 4> weight{0, 0, 0, 0};
    Vec3 p = s.w[0];
    if (s.n == 1) {
        weight[0] = 1;
    } else if (s.n == 2) {
        p = closestOnSegment(s.w[0], s.w[1], weight[0], weight[1]);
    } else if (s.n == 3) {
        std::array<Real, 3> w3{};
        p = closestOnTriangle(s.w[0], s.w[1], s.w[2], w3);
        weight = {w3[0], w3[1], w3[2], 0};
    } else {
        // Test each face whose plane separates the origin from the opposite vertex.
        static constexpr int kFaces[4][4] = {
            {0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {1, 3, 2, 0}};
        Real best = std::numeric_limits<Real>::infinity();
        bool any_outside = false;
        for (const auto& f : kFaces) {
            const Vec3& a = s.w[f[0]];
            const Vec3& b = s.w[f[1]];
            const Vec3& c = s.w[f[2]];
            const Vec3& d = s.w[f[3]];
            const Vec3 n = (b - a).cross(c - a);
            const Real sign_p = -a.dot(n);
            const Real sign_d = (d - a).dot(n);
            const bool degenerate =
                std::abs(sign_d) <= kDegenerateRelative * n.norm() * (d - a).norm();
            if (!degenerate && sign_p * sign_d >= 0) continue;  // origin on d's side
            any_outside = true;
            std::array<Real, 3> w3{};
            const Vec3 q = closestOnTriangle(a, b, c, w3);
            const Real q2 = q.squaredNorm();
            if (q2 < best) {
                best = q2;
                p = q;
                weight = {0, 0, 0, 0};
                weight[f[0]] = w3[0];
                weight[f[1]] = w3[1];
                weight[f[2]] = w3[2];
            }
        }
        if (!any_outside) {
            enclosed = true;
            return Vec3::Zero();
        }
    }
    Simplex reduced;
    for (int i = 0; i < s.n; ++i) {
        if (weight[i] > 0) reduced.w[reduced.n++] = s.w[i];
    }
    if (reduced.n == 0) reduced.w[reduced.n++] = s.w[0];
    s = reduced;
    return p;
}

Real maxNorm(const Simplex& s) {
    Real m = 0;
    for (int i = 0; i < s.n; ++i) m = std::max(m, s.w[i].norm());
    return m;
}

// ---- Bounded EPA: decides whether the penetration depth of the cores exceeds `threshold`. ----

struct EpaFace {
    std::array<int, 3> v{};
    Vec3 normal = Vec3::Zero();  // unit, outward; zero for a degenerate face
    Real dist = 0;               // normal . vertex: signed distance of the plane from the origin
    bool valid = true;
};

constexpr int kEpaMaxVertices = kGjkMaxIterations + 4;
constexpr int kEpaMaxFaces = 2 * kEpaMaxVertices;

struct EpaPolytope {
    std::array<Vec3, kEpaMaxVertices> w{};
    int vertex_count = 0;
    std::array<EpaFace, kEpaMaxFaces> faces{};
    int face_count = 0;
    Real eps = 0;

    bool addFace(int i, int j, int k) {
        if (face_count >= kEpaMaxFaces) return false;
        EpaFace& f = faces[face_count++];
        f.v = {i, j, k};
        f.valid = true;
        const Vec3 n = (w[j] - w[i]).cross(w[k] - w[i]);
        const Real len = n.norm();
        if (len > eps * eps) {
            f.normal = n / len;
            f.dist = f.normal.dot(w[i]);
        } else {
            f.normal = Vec3::Zero();
            f.dist = std::numeric_limits<Real>::infinity();
        }
        return true;
    }
};

ContactState epaDecide(const MinkowskiDifference& cso, const Simplex& start, Real threshold,
                       Real scale, std::int32_t& iterations) {
    EpaPolytope poly;
    poly.eps = std::max(Real(64) * kEpsilon * scale, std::numeric_limits<Real>::min());
    for (int i = 0; i < start.n; ++i) poly.w[poly.vertex_count++] = start.w[i];

    // Direction probes: any direction n with support h(n) <= threshold proves depth <= threshold.
    auto probe = [&](const Vec3& dir, Vec3& w_out) {
        w_out = cso.support(dir);
        return dir.dot(w_out) <= threshold;
    };

    // Blow a lower-dimensional simplex up to a tetrahedron (the CSO is 3-D unless it is flat, and
    // a flat CSO has penetration depth zero).
    while (poly.vertex_count < 4) {
        const Vec3 w0 = poly.w[0];
        std::array<Vec3, 6> dirs{};
        int dir_count = 0;
        if (poly.vertex_count == 1) {
            dirs = {Vec3::UnitX(),  -Vec3::UnitX(), Vec3::UnitY(),
                    -Vec3::UnitY(), Vec3::UnitZ(),  -Vec3::UnitZ()};
            dir_count = 6;
        } else if (poly.vertex_count == 2) {
            const Vec3 e = poly.w[1] - w0;
            int axis = 0;
            e.cwiseAbs().minCoeff(&axis);
            const Vec3 d1 = e.cross(Vec3::Unit(axis)).normalized();
            const Vec3 d2 = e.cross(d1).normalized();
            dirs = {d1, -d1, d2, -d2, Vec3::Zero(), Vec3::Zero()};
            dir_count = 4;
        } else {
            const Vec3 n = (poly.w[1] - w0).cross(poly.w[2] - w0);
            const Real len = n.norm();
            if (!(len > poly.eps * poly.eps)) return ContactState::Touching;
            dirs = {n / len, -n / len, Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
            dir_count = 2;
        }
        bool grown = false;
        for (int k = 0; k < dir_count && !grown; ++k) {
            Vec3 w;
            if (probe(dirs[k], w)) return ContactState::Touching;
            Real off = 0;
            if (poly.vertex_count == 1) {
                off = (w - w0).norm();
            } else if (poly.vertex_count == 2) {
                const Vec3 e = poly.w[1] - w0;
                off = e.cross(w - w0).norm() / e.norm();
            } else {
                off = std::abs(dirs[k].dot(w - w0));
            }
            if (off > poly.eps) {
                poly.w[poly.vertex_count++] = w;
                grown = true;
            }
        }
        if (!grown) return ContactState::Touching;  // flat CSO: zero depth
    }

    // Outward orientation of the initial tetrahedron (see RTCD 5.1.6 face order).
    if ((poly.w[1] - poly.w[0]).cross(poly.w[2] - poly.w[0]).dot(poly.w[3] - poly.w[0]) > 0) {
        std::swap(poly.w[1], poly.w[2]);
    }
    poly.addFace(0, 1, 2);
    poly.addFace(0, 3, 1);
    poly.addFace(0, 2, 3);
    poly.addFace(1, 3, 2);

    for (int iter = 0; iter < kGjkMaxIterations; ++iter) {
        ++iterations;
        int best = -1;
        for (int f = 0; f < poly.face_count; ++f) {
            const EpaFace& face = poly.faces[f];
            if (!face.valid || face.normal.isZero()) continue;
            if (best < 0 || face.dist < poly.faces[best].dist) best = f;
        }
        if (best < 0) return ContactState::Failed;
        const EpaFace closest = poly.faces[best];
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
        const Real dup = kDuplicateRelative * std::max(w.norm(), scale);
        for (int i = 0; i < poly.vertex_count; ++i) {
            if ((poly.w[i] - w).squaredNorm() <= dup * dup) return ContactState::Touching;
        }
        if (poly.vertex_count >= kEpaMaxVertices) return ContactState::Failed;
        const int new_index = poly.vertex_count;
        poly.w[poly.vertex_count++] = w;

        // Remove the faces w sees; the horizon is their boundary (edges whose twin survives).
        std::array<std::array<int, 2>, 3 * kEpaMaxFaces> edges{};
        int edge_count = 0;
        for (int f = 0; f < poly.face_count; ++f) {
            EpaFace& face = poly.faces[f];
            if (!face.valid) continue;
            const bool visible =
                face.normal.isZero() || face.normal.dot(w - poly.w[face.v[0]]) > poly.eps * 0.5;
            if (!visible) continue;
            face.valid = false;
            for (int e = 0; e < 3; ++e) {
                const int i = face.v[e];
                const int j = face.v[(e + 1) % 3];
                // An edge shared by two removed faces appears in both directions: cancel it.
                bool cancelled = false;
                for (int k = 0; k < edge_count; ++k) {
                    if (edges[k][0] == j && edges[k][1] == i) {
                        edges[k] = edges[--edge_count];
                        cancelled = true;
                        break;
                    }
                }
                if (!cancelled) edges[edge_count++] = {i, j};
            }
        }
        // Compact the face list, then close the hole with a fan to w.
        int kept = 0;
        for (int f = 0; f < poly.face_count; ++f) {
            if (poly.faces[f].valid) poly.faces[kept++] = poly.faces[f];
        }
        poly.face_count = kept;
        for (int k = 0; k < edge_count; ++k) {
            if (!poly.addFace(edges[k][0], edges[k][1], new_index)) return ContactState::Failed;
        }
    }
    return ContactState::Failed;
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

RelativePose relativePose(const Pose& pose_a, const Pose& pose_b) {
    const Quat inv_a = pose_a.orientation.conjugate();
    RelativePose rel;
    rel.rotation = (inv_a * pose_b.orientation).toRotationMatrix();
    rel.position = inv_a * (pose_b.position - pose_a.position);
    return rel;
}

GjkOutput gjkDistance(const ConvexCore& a, const ConvexCore& b, const RelativePose& b_in_a,
                      Real scale) {
    const MinkowskiDifference cso{a, b, b_in_a};
    GjkOutput out;
    out.lower_bound = -std::numeric_limits<Real>::infinity();
    const Real tiny = std::max(kOverlapRelative * scale, std::numeric_limits<Real>::min());

    Simplex s;
    // Any point of A - B starts the search; -position points from B's origin towards A's.
    s.w[0] = cso.support(-b_in_a.position);
    s.n = 1;
    Vec3 v = s.w[0];
    auto overlapping = [&]() {
        out.state = GjkState::Overlapping;
        out.distance = 0;
        out.lower_bound = std::max(out.lower_bound, Real(0));
        out.simplex_count = s.n;
        for (int i = 0; i < s.n; ++i) out.simplex[i] = s.w[i];
    };
    auto separated = [&](Real vv) {
        out.state = GjkState::Separated;
        out.distance = std::sqrt(vv);
        out.simplex_count = s.n;
        for (int i = 0; i < s.n; ++i) out.simplex[i] = s.w[i];
    };

    for (int iter = 0; iter < kGjkMaxIterations; ++iter) {
        out.iterations = iter + 1;
        const Real vv = v.squaredNorm();
        const Real noise = std::max(kOverlapRelative * maxNorm(s), tiny);
        if (vv <= noise * noise) {
            overlapping();
            return out;
        }
        const Vec3 w = cso.support(-v);
        const Real vw = v.dot(w);
        // Every point x of A - B has v.x >= v.w, so distance >= v.w / |v| (a separating plane).
        out.lower_bound = std::max(out.lower_bound, vw / std::sqrt(vv));
        if (vv - vw <= kGjkRelativeTolerance * vv) {
            separated(vv);
            return out;
        }
        const Real dup = kDuplicateRelative * std::max(w.norm(), maxNorm(s));
        for (int i = 0; i < s.n; ++i) {
            if ((s.w[i] - w).squaredNorm() <= dup * dup) {
                // No new support point: |v| is as good as rounding allows.
                separated(vv);
                return out;
            }
        }
        const Simplex before = s;
        s.w[s.n++] = w;
        bool enclosed = false;
        const Vec3 v_next = closestOnSimplex(s, enclosed);
        if (enclosed) {
            overlapping();
            return out;
        }
        if (!(v_next.squaredNorm() < vv)) {
            // |v| must decrease strictly (van den Bergen 1999 §4); rounding stalled it.
            s = before;
            separated(vv);
            return out;
        }
        v = v_next;
    }
    out.state = GjkState::Failed;
    out.distance = v.norm();
    out.simplex_count = s.n;
    for (int i = 0; i < s.n; ++i) out.simplex[i] = s.w[i];
    return out;
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

CollideOutput collideConvexCores(const ConvexCore& a, const ConvexCore& b,
                                 const RelativePose& b_in_a, Real tolerance, Real scale) {
    const GjkOutput g = gjkDistance(a, b, b_in_a, scale);
    const Real radii = a.radius + b.radius;
    CollideOutput out;
    switch (g.state) {
        case GjkState::Separated:
            // Inflating both cores by their radii shifts the signed distance by the radii.
            out = classifySignedDistance(g.distance - radii, tolerance);
            break;
        case GjkState::Overlapping:
            if (radii > tolerance) {
                out.state = ContactState::Penetrating;  // depth >= radii
            } else {
                Simplex start;
                start.n = g.simplex_count;
                for (int i = 0; i < g.simplex_count; ++i) start.w[i] = g.simplex[i];
                const MinkowskiDifference cso{a, b, b_in_a};
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

}  // namespace collision
