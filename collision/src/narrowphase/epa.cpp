// collision/src/narrowphase/epa.cpp -- GJK with witness points (van den Bergen 1999 §3: every
// simplex vertex w = a - b keeps a and b; the closest point's barycentric weights combine them) and
// the expanding polytope algorithm (van den Bergen 2001 §4; RTCD 9.5 for the simplex sub-steps).
// Invariants: both loops are capped (kGjkMaxIterations, kEpaMaxIterations) and report Failed;
// every division is guarded by a scale-relative epsilon, so finite input never yields NaN; faces
// and horizon edges are visited in index order, so the output is deterministic.
#include "narrowphase/epa.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace collision {

namespace {

// Lengths below these multiples of kEpsilon * (size of the simplex) are rounding noise
// (the same thresholds as gjk.cpp, so both GJKs agree on "overlapping").
constexpr Real kOverlapRelative = Real(32) * kEpsilon;
constexpr Real kDuplicateRelative = Real(8) * kEpsilon;
constexpr Real kDegenerateRelative = Real(1e3) * kEpsilon;

// Support of A - B in direction `dir` (A's frame), with both support points.
struct Cso {
    const ConvexCore& a;
    const ConvexCore& b;
    const RelativePose& b_in_a;

    SupportVertex support(const Vec3& dir) const {
        SupportVertex s;
        const Vec3 dir_in_b = b_in_a.rotation.transpose() * (-dir);
        s.a = a.support(dir);
        s.b = b_in_a.rotation * b.support(dir_in_b) + b_in_a.position;
        s.w = s.a - s.b;
        return s;
    }
};

// Closest point to the origin on segment pq: weights (1 - t, t). RTCD 5.1.2.
void segmentWeights(const Vec3& p, const Vec3& q, Real& wp, Real& wq) {
    const Vec3 pq = q - p;
    const Real len2 = pq.squaredNorm();
    const Real num = -p.dot(pq);
    if (num <= 0 || !(len2 > 0)) {
        wp = 1;
        wq = 0;
    } else if (num >= len2) {
        wp = 0;
        wq = 1;
    } else {
        wq = num / len2;
        wp = 1 - wq;
    }
}

// Closest point to the origin on triangle pqr by Voronoi regions (RTCD 5.1.5); weights in w.
// In the face region the point is the plane projection n (n.p) / |n|^2 with signed-area weights:
// for slivers far from the origin p + v pq + t pr loses accuracy like |p|^2 / area, enough to
// stall GJK at a wrong distance (a 3e-5-thin box touching a 5-unit box came out 6e-6 apart).
Vec3 triangleClosest(const Vec3& p, const Vec3& q, const Vec3& r, std::array<Real, 3>& w) {
    const Vec3 pq = q - p;
    const Vec3 pr = r - p;
    const Real d1 = -pq.dot(p);
    const Real d2 = -pr.dot(p);
    if (d1 <= 0 && d2 <= 0) {
        w = {1, 0, 0};
        return p;
    }
    const Real d3 = -pq.dot(q);
    const Real d4 = -pr.dot(q);
    if (d3 >= 0 && d4 <= d3) {
        w = {0, 1, 0};
        return q;
    }
    const Real vr = d1 * d4 - d3 * d2;
    if (vr <= 0 && d1 >= 0 && d3 <= 0) {
        const Real t = d1 / (d1 - d3);
        w = {1 - t, t, 0};
        return p + t * pq;
    }
    const Real d5 = -pq.dot(r);
    const Real d6 = -pr.dot(r);
    if (d6 >= 0 && d5 <= d6) {
        w = {0, 0, 1};
        return r;
    }
    const Real vq = d5 * d2 - d1 * d6;
    if (vq <= 0 && d2 >= 0 && d6 <= 0) {
        const Real t = d2 / (d2 - d6);
        w = {1 - t, 0, t};
        return p + t * pr;
    }
    const Real vp = d3 * d6 - d5 * d4;
    if (vp <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const Real t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        w = {0, 1 - t, t};
        return q + t * (r - q);
    }
    const Real denom = vp + vq + vr;
    if (!(denom > kDegenerateRelative * pq.squaredNorm() * pr.squaredNorm())) {
        // Sliver: the face region is unreliable, take the nearest edge.
        Real a = 0;
        Real b = 0;
        segmentWeights(p, q, a, b);
        std::array<Real, 3> best{a, b, 0};
        Real best2 = (a * p + b * q).squaredNorm();
        segmentWeights(q, r, a, b);
        if ((a * q + b * r).squaredNorm() < best2) {
            best = {0, a, b};
            best2 = (a * q + b * r).squaredNorm();
        }
        segmentWeights(r, p, a, b);
        if ((a * r + b * p).squaredNorm() < best2) best = {b, 0, a};
        w = best;
        return best[0] * p + best[1] * q + best[2] * r;
    }
    const Vec3 n = pq.cross(pr);
    const Real nn = n.squaredNorm();
    if (nn > 0) {
        const Vec3 x = n * (n.dot(p) / nn);
        const Real wp = n.dot((q - x).cross(r - x)) / nn;
        const Real wq = n.dot((r - x).cross(p - x)) / nn;
        w = {wp, wq, 1 - wp - wq};
        return x;
    }
    const Real v = vq / denom;
    const Real t = vr / denom;
    w = {1 - v - t, v, t};
    return p + v * pq + t * pr;
}

// Closest point of the simplex to the origin; reduces the simplex to the vertices with positive
// weight and fills their weights. `enclosed` when a tetrahedron holds the origin (RTCD 5.1.6).
Vec3 reduceSimplex(WitnessSimplex& s, std::array<Real, 4>& weight, bool& enclosed) {
    enclosed = false;
    weight = {0, 0, 0, 0};
    Vec3 point = s.v[0].w;
    if (s.n == 1) {
        weight[0] = 1;
    } else if (s.n == 2) {
        segmentWeights(s.v[0].w, s.v[1].w, weight[0], weight[1]);
        point = weight[0] * s.v[0].w + weight[1] * s.v[1].w;
    } else if (s.n == 3) {
        std::array<Real, 3> w3{};
        point = triangleClosest(s.v[0].w, s.v[1].w, s.v[2].w, w3);
        weight = {w3[0], w3[1], w3[2], 0};
    } else {
        static constexpr int kFaces[4][4] = {
            {0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {1, 3, 2, 0}};
        Real best = std::numeric_limits<Real>::infinity();
        bool outside_any = false;
        for (const auto& f : kFaces) {
            const Vec3& p = s.v[f[0]].w;
            const Vec3& q = s.v[f[1]].w;
            const Vec3& r = s.v[f[2]].w;
            const Vec3& o = s.v[f[3]].w;
            const Vec3 n = (q - p).cross(r - p);
            const Real side_origin = -p.dot(n);
            const Real side_opposite = (o - p).dot(n);
            const bool flat =
                std::abs(side_opposite) <= kDegenerateRelative * n.norm() * (o - p).norm();
            if (!flat && side_origin * side_opposite >= 0) continue;  // origin on o's side
            outside_any = true;
            std::array<Real, 3> w3{};
            const Vec3 x = triangleClosest(p, q, r, w3);
            const Real d2 = x.squaredNorm();
            if (d2 < best) {
                best = d2;
                point = x;
                weight = {0, 0, 0, 0};
                weight[f[0]] = w3[0];
                weight[f[1]] = w3[1];
                weight[f[2]] = w3[2];
            }
        }
        if (!outside_any) {
            enclosed = true;
            return Vec3::Zero();
        }
    }
    WitnessSimplex reduced;
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
    return point;
}

Real maxNorm(const WitnessSimplex& s) {
    Real m = 0;
    for (int i = 0; i < s.n; ++i) m = std::max(m, s.v[i].w.norm());
    return m;
}

void combine(const WitnessSimplex& s, const std::array<Real, 4>& weight, Vec3& pa, Vec3& pb) {
    pa.setZero();
    pb.setZero();
    for (int i = 0; i < s.n; ++i) {
        pa += weight[i] * s.v[i].a;
        pb += weight[i] * s.v[i].b;
    }
}

// ---- EPA polytope ----

// Set entirely by Polytope::addFace; no default values, so the face array costs no zeroing.
struct Face {
    std::array<int, 3> v;
    Vec3 normal;  // unit outward; zero when degenerate
    Real dist;    // normal . vertex
    bool valid;
};

constexpr int kMaxVertices = kEpaMaxIterations + 4;
constexpr int kMaxFaces = 2 * kMaxVertices;

struct Polytope {
    // Only the first vertex_count / face_count entries are set (no zeroing of ~22 kB per call).
    std::array<SupportVertex, kMaxVertices> vert;
    int vertex_count = 0;
    std::array<Face, kMaxFaces> faces;
    int face_count = 0;
    Real eps = 0;

    bool addFace(int i, int j, int k) {
        if (face_count >= kMaxFaces) return false;
        Face& f = faces[static_cast<std::size_t>(face_count++)];
        f.v = {i, j, k};
        f.valid = true;
        const Vec3& p = vert[static_cast<std::size_t>(i)].w;
        const Vec3 n = (vert[static_cast<std::size_t>(j)].w - p)
                           .cross(vert[static_cast<std::size_t>(k)].w - p);
        const Real len = n.norm();
        if (len > eps * eps) {
            f.normal = n / len;
            f.dist = f.normal.dot(p);
        } else {
            f.normal.setZero();
            f.dist = std::numeric_limits<Real>::infinity();
        }
        return true;
    }
};

// Writes the output for face f: the origin's projection n * dist expressed in the face's
// vertices, and the same weights applied to their support points.
void faceOutput(const Polytope& poly, const Face& f, EpaOutput& out) {
    const SupportVertex& p = poly.vert[static_cast<std::size_t>(f.v[0])];
    const SupportVertex& q = poly.vert[static_cast<std::size_t>(f.v[1])];
    const SupportVertex& r = poly.vert[static_cast<std::size_t>(f.v[2])];
    std::array<Real, 3> w{};
    triangleClosest(p.w, q.w, r.w, w);
    out.normal = f.normal;
    out.depth = f.dist;
    out.point_a = w[0] * p.a + w[1] * q.a + w[2] * r.a;
    out.point_b = w[0] * p.b + w[1] * q.b + w[2] * r.b;
}

}  // namespace

GjkWitnessOutput gjkWitness(const ConvexCore& a, const ConvexCore& b, const RelativePose& b_in_a,
                            Real scale) {
    const Cso cso{a, b, b_in_a};
    GjkWitnessOutput out;
    const Real tiny = std::max(kOverlapRelative * scale, std::numeric_limits<Real>::min());
    WitnessSimplex& s = out.simplex;
    s.v[0] = cso.support(-b_in_a.position);
    s.n = 1;
    Vec3 v = s.v[0].w;
    out.point_a = s.v[0].a;
    out.point_b = s.v[0].b;

    for (int iter = 0; iter < kGjkMaxIterations; ++iter) {
        out.iterations = iter + 1;
        const Real vv = v.squaredNorm();
        const Real noise = std::max(kOverlapRelative * maxNorm(s), tiny);
        if (vv <= noise * noise) {
            out.state = GjkState::Overlapping;
            out.distance = 0;
            return out;
        }
        const SupportVertex w = cso.support(-v);
        const Real vw = v.dot(w.w);
        // van den Bergen 1999 §4: |v|^2 - v.w bounds |v|^2 - |v| dist(origin, A - B).
        if (vv - vw <= kGjkRelativeTolerance * vv) {
            out.state = GjkState::Separated;
            out.distance = std::sqrt(vv);
            return out;
        }
        const Real dup = kDuplicateRelative * std::max(w.w.norm(), maxNorm(s));
        for (int i = 0; i < s.n; ++i) {
            if ((s.v[i].w - w.w).squaredNorm() <= dup * dup) {
                out.state = GjkState::Separated;  // no new support point: rounding-limited
                out.distance = std::sqrt(vv);
                return out;
            }
        }
        const WitnessSimplex before = s;
        s.v[s.n++] = w;
        std::array<Real, 4> weight{};
        bool enclosed = false;
        const Vec3 v_next = reduceSimplex(s, weight, enclosed);
        if (enclosed) {
            out.state = GjkState::Overlapping;
            out.distance = 0;
            return out;
        }
        Vec3 pa;
        Vec3 pb;
        combine(s, weight, pa, pb);
        if (!(v_next.squaredNorm() < vv)) {
            s = before;  // |v| must decrease strictly; rounding stalled it
            out.state = GjkState::Separated;
            out.distance = std::sqrt(vv);
            return out;
        }
        v = v_next;
        out.point_a = pa;
        out.point_b = pb;
    }
    out.state = GjkState::Failed;
    out.distance = v.norm();
    return out;
}

EpaOutput epaPenetration(const ConvexCore& a, const ConvexCore& b, const RelativePose& b_in_a,
                         const WitnessSimplex& start, Real scale) {
    const Cso cso{a, b, b_in_a};
    EpaOutput out;
    Polytope poly;
    poly.eps = std::max(Real(64) * kEpsilon * scale, std::numeric_limits<Real>::min());
    const Real tol = std::max(kEpaRelativeTolerance * scale, std::numeric_limits<Real>::min());
    for (int i = 0; i < start.n; ++i)
        poly.vert[static_cast<std::size_t>(poly.vertex_count++)] =
            start.v[static_cast<std::size_t>(i)];

    // Every probed direction n gives an upper bound h(n) on the depth; the best one answers when
    // the obstacle is flat (zero volume) and the polytope cannot grow to a tetrahedron.
    Real best_h = std::numeric_limits<Real>::infinity();
    auto probe = [&](const Vec3& dir) {
        const SupportVertex s = cso.support(dir);
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
        if (++out.iterations > kEpaMaxIterations) return out;  // Failed
        const Vec3 w0 = poly.vert[0].w;
        std::array<Vec3, 6> dirs{};
        int dir_count = 0;
        if (poly.vertex_count == 1) {
            dirs = {Vec3::UnitX(),  -Vec3::UnitX(), Vec3::UnitY(),
                    -Vec3::UnitY(), Vec3::UnitZ(),  -Vec3::UnitZ()};
            dir_count = 6;
        } else if (poly.vertex_count == 2) {
            const Vec3 e = poly.vert[1].w - w0;
            const Real e_len = e.norm();
            if (!(e_len > poly.eps)) {
                poly.vertex_count = 1;  // duplicate vertex: restart from one
                continue;
            }
            int axis = 0;
            e.cwiseAbs().minCoeff(&axis);
            const Vec3 d1 = e.cross(Vec3::Unit(axis)).normalized();
            const Vec3 d2 = (e / e_len).cross(d1);
            dirs = {d1, -d1, d2, -d2, Vec3::Zero(), Vec3::Zero()};
            dir_count = 4;
        } else {
            const Vec3 n = (poly.vert[1].w - w0).cross(poly.vert[2].w - w0);
            const Real len = n.norm();
            if (!(len > poly.eps * poly.eps)) {
                poly.vertex_count = 2;  // collinear: drop the third vertex and probe again
                continue;
            }
            dirs = {n / len, -n / len, Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
            dir_count = 2;
        }
        bool grown = false;
        for (int k = 0; k < dir_count && !grown; ++k) {
            const SupportVertex s = probe(dirs[static_cast<std::size_t>(k)]);
            Real off = 0;
            if (poly.vertex_count == 1) {
                off = (s.w - w0).norm();
            } else if (poly.vertex_count == 2) {
                const Vec3 e = poly.vert[1].w - w0;
                off = e.cross(s.w - w0).norm() / e.norm();
            } else {
                off = std::abs(dirs[static_cast<std::size_t>(k)].dot(s.w - w0));
            }
            if (off > poly.eps) {
                poly.vert[static_cast<std::size_t>(poly.vertex_count++)] = s;
                grown = true;
            }
        }
        if (!grown) {
            // Flat obstacle: the best probe's plane is the answer (depth 0 up to rounding).
            out.state = std::isfinite(best_h) ? EpaState::Converged : EpaState::Failed;
            return out;
        }
    }

    // Outward orientation of the tetrahedron (RTCD 5.1.6 face order).
    if ((poly.vert[1].w - poly.vert[0].w)
            .cross(poly.vert[2].w - poly.vert[0].w)
            .dot(poly.vert[3].w - poly.vert[0].w) > 0) {
        std::swap(poly.vert[1], poly.vert[2]);
    }
    poly.addFace(0, 1, 2);
    poly.addFace(0, 3, 1);
    poly.addFace(0, 2, 3);
    poly.addFace(1, 3, 2);

    std::array<std::array<int, 2>, 3 * kMaxFaces> edges;  // the first edge_count are set
    for (int iter = 0; iter < kEpaMaxIterations; ++iter) {
        ++out.iterations;
        int best = -1;
        for (int f = 0; f < poly.face_count; ++f) {
            const Face& face = poly.faces[static_cast<std::size_t>(f)];
            if (!face.valid || face.normal.isZero()) continue;
            if (best < 0 || face.dist < poly.faces[static_cast<std::size_t>(best)].dist) best = f;
        }
        if (best < 0) {
            out.state = EpaState::Failed;
            return out;
        }
        const Face closest = poly.faces[static_cast<std::size_t>(best)];
        const SupportVertex w = cso.support(closest.normal);
        const Real h = closest.normal.dot(w.w);
        // Lower bound closest.dist <= depth <= h (van den Bergen 2001 §4).
        bool converged = h - closest.dist <= tol;
        if (!converged) {
            const Real dup = kDuplicateRelative * std::max(w.w.norm(), scale);
            for (int i = 0; i < poly.vertex_count && !converged; ++i) {
                converged =
                    (poly.vert[static_cast<std::size_t>(i)].w - w.w).squaredNorm() <= dup * dup;
            }
        }
        if (converged) {
            // Coplanar faces (a split face of the obstacle) share the distance; the origin's
            // projection lies in the one whose closest point to the origin is nearest.
            Face chosen = closest;
            Real chosen2 = std::numeric_limits<Real>::infinity();
            for (int f = 0; f < poly.face_count; ++f) {
                const Face& face = poly.faces[static_cast<std::size_t>(f)];
                if (!face.valid || face.normal.isZero() || face.dist > closest.dist + tol) continue;
                std::array<Real, 3> wt{};
                const Real d2 =
                    triangleClosest(poly.vert[static_cast<std::size_t>(face.v[0])].w,
                                    poly.vert[static_cast<std::size_t>(face.v[1])].w,
                                    poly.vert[static_cast<std::size_t>(face.v[2])].w, wt)
                        .squaredNorm();
                if (d2 < chosen2) {
                    chosen2 = d2;
                    chosen = face;
                }
            }
            faceOutput(poly, chosen, out);
            out.state = EpaState::Converged;
            return out;
        }
        if (poly.vertex_count >= kMaxVertices) break;
        const int new_index = poly.vertex_count;
        poly.vert[static_cast<std::size_t>(poly.vertex_count++)] = w;

        // Remove the faces that see w; their boundary (edges not shared by two removed faces)
        // is the horizon, closed by a fan to w.
        int edge_count = 0;
        for (int f = 0; f < poly.face_count; ++f) {
            Face& face = poly.faces[static_cast<std::size_t>(f)];
            if (!face.valid) continue;
            const bool visible =
                face.normal.isZero() ||
                face.normal.dot(w.w - poly.vert[static_cast<std::size_t>(face.v[0])].w) >
                    poly.eps * Real(0.5);
            if (!visible) continue;
            face.valid = false;
            for (int e = 0; e < 3; ++e) {
                const int i = face.v[static_cast<std::size_t>(e)];
                const int j = face.v[static_cast<std::size_t>((e + 1) % 3)];
                bool cancelled = false;
                for (int k = 0; k < edge_count; ++k) {
                    auto& edge = edges[static_cast<std::size_t>(k)];
                    if (edge[0] == j && edge[1] == i) {
                        edge = edges[static_cast<std::size_t>(--edge_count)];
                        cancelled = true;
                        break;
                    }
                }
                if (!cancelled) edges[static_cast<std::size_t>(edge_count++)] = {i, j};
            }
        }
        int kept = 0;
        for (int f = 0; f < poly.face_count; ++f) {
            if (poly.faces[static_cast<std::size_t>(f)].valid) {
                poly.faces[static_cast<std::size_t>(kept++)] =
                    poly.faces[static_cast<std::size_t>(f)];
            }
        }
        poly.face_count = kept;
        for (int k = 0; k < edge_count; ++k) {
            const auto& edge = edges[static_cast<std::size_t>(k)];
            if (!poly.addFace(edge[0], edge[1], new_index)) {
                out.state = EpaState::Failed;
                return out;
            }
        }
    }
    out.state = EpaState::Failed;
    return out;
}

}  // namespace collision
