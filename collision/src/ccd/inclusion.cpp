// collision/src/ccd/inclusion.cpp -- conservative vertex-face and edge-edge CCD by inclusion
// (interval subdivision of the parameter box (t, u, v)), in the style of Tight-Inclusion:
// Wang, Ferguson, Schneider, Jiang, Attene, Panozzo, "A Large-scale Benchmark and an
// Inclusion-based Algorithm for Continuous Collision Detection", ACM TOG 40(5), 2021.
//
// Invariant: the priority queue plus the boxes already excluded cover the whole parameter
// domain, and an excluded box provably holds no root (the error bound below is rigorous), so
// the true first root always lies in a queued box whose t_lo <= t_root. Boxes are popped in
// order of t_lo, so the t returned (the popped box's t_lo) is never later than the first
// contact, and a Separated answer is never a false negative.
//
// Exclusion. A box is dropped when its image provably misses the origin (inflated by the min
// separation). F is multilinear, so the image lies in the convex hull of the 8 corner values:
// per coordinate axis that is the corners' range; along any direction n it is the range of
// n . F over the corners. Three projections are tried: the axes, the primitives' plane normal
// at the box's mid time (a vertex or edge sliding close and parallel to the other primitive,
// the spike/crack/wedge queries, is excluded in one box instead of ~10^4 thin (u, v) cells),
// and the mean corner value (the direction towards a small image, which also separates a
// vertex passing just outside a face's edge in its plane). Each carries its rounding bound.
//
// Search order. Boxes are split on the variable that moves F most (largest corner difference),
// except that t is bisected first whenever one half of the box's t interval is provably empty
// (look-ahead): along a curve or patch of contacts (parallel edges, a collinear face, a large
// min separation) this resolves t while u, v stay coarse, instead of refining many u, v cells
// that would each need their own proof that the early half is empty. With min_separation > 0
// a box whose whole image lies inside the separation band is all contact: its start bounds the
// first contact from above, so the search stops once [t_lo of the queue, that start] is within
// CcdSettings::time_tolerance.
//
// Guarantee. Hit: a point of the returned box comes within min_separation + the acceptance
// width (tolerance * size, >= 4x the rounding bound) of contact, in max norm; t <= the first
// exact contact. Separated: no contact within min_separation (no false negatives). Failed:
// cap reached; t is a safe lower bound.
//
// Why this method rather than root isolation of the coplanarity cubic (the other
// option): the cubic only finds coplanar instants; the degenerate cases that matter most in
// the sample queries (motion coplanar for the whole step, parallel edges, zero-area faces) make
// the cubic identically zero or ill-conditioned and need separate exact 2D sub-cases, each of
// which would need its own exact predicates. The inclusion function handles them all with one
// uniform argument: F is multilinear, so its exact range on a box is spanned by 8 corner values
// and only their rounding error has to be bounded. Cost is the subdivision, which is bounded
// by CcdSettings::max_boxes (-> Failed with a safe t, never a hang).
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "collision/ccd/ccd.h"

namespace collision {
namespace {

enum class PrimitivePair { VertexFace, EdgeEdge };

/// One axis-aligned box of the parameter domain [0,1]^3 in (t, u, v). Bounds are dyadic
/// rationals (produced by halving), so midpoints and 1 - u - v are computed exactly as long as
/// widths stay >= kMinWidth.
struct ParamBox {
    double t_lo, t_hi, u_lo, u_hi, v_lo, v_hi;
    int depth;
};

/// Heap order: smallest t_lo on top; on ties the deeper box first (dives towards a hit).
struct LaterBox {
    bool operator()(const ParamBox& a, const ParamBox& b) const {
        if (a.t_lo != b.t_lo) return a.t_lo > b.t_lo;
        return a.depth < b.depth;
    }
};

/// 2^-45: far above 2^-52, so 1 - u - v and (lo + hi) / 2 stay exact for dyadic bounds.
constexpr double kMinWidth = 0x1p-45;

/// The 8 input points as plain doubles, with per-axis error bounds.
struct Query {
    PrimitivePair pair;
    double x0[4][3];  ///< positions at t = 0
    double dx[4][3];  ///< fl(x1 - x0), the same rounding the error bound accounts for
    double err[3];    ///< bound on |computed F - exact F| at any corner, per axis
    /// Per-axis coefficient of the error of a projection n . F: err plus the rounding of the
    /// three-term dot product (see excludedAlong).
    double dir_err[3];
    double gap;       ///< min_separation
    double accept;    ///< acceptance width of the image box
};

/// F at the 8 corners of `box`, per axis: vals[(it << 2) | (iu << 1) | iv][axis].
/// Vertex-face: F = p(t) - ((1-u-v) f0(t) + u f1(t) + v f2(t)).
/// Edge-edge:   F = ((1-u) a0(t) + u a1(t)) - ((1-v) b0(t) + v b1(t)).
/// Each point moves as x(t) = x0 + t (x1 - x0). F is multilinear in (t, u, v) (degree one in
/// each variable alone), so on a box its exact range per axis is spanned by the corner values.
void cornerValues(const Query& q, const ParamBox& box, double vals[8][3]) {
    const double ts[2] = {box.t_lo, box.t_hi};
    const double us[2] = {box.u_lo, box.u_hi};
    const double vs[2] = {box.v_lo, box.v_hi};
    for (int it = 0; it < 2; ++it) {
        double p[4][3];
        for (int i = 0; i < 4; ++i) {
            for (int a = 0; a < 3; ++a) p[i][a] = q.x0[i][a] + ts[it] * q.dx[i][a];
        }
        for (int iu = 0; iu < 2; ++iu) {
            for (int iv = 0; iv < 2; ++iv) {
                const double u = us[iu];
                const double v = vs[iv];
                double* out = vals[(it << 2) | (iu << 1) | iv];
                if (q.pair == PrimitivePair::VertexFace) {
                    const double w0 = 1.0 - u - v;  // exact: dyadic u, v (see kMinWidth)
                    for (int a = 0; a < 3; ++a) {
                        out[a] = p[0][a] - ((w0 * p[1][a] + u * p[2][a]) + v * p[3][a]);
                    }
                } else {
                    const double wu = 1.0 - u;
                    const double wv = 1.0 - v;
                    for (int a = 0; a < 3; ++a) {
                        out[a] = (wu * p[0][a] + u * p[1][a]) - (wv * p[2][a] + v * p[3][a]);
                    }
                }
            }
        }
    }
}

/// Rigorous per-axis bound on the rounding error of cornerValues, u = 2^-53, M = max |input|
/// on that axis (first-order analysis, Higham "Accuracy and Stability" §2-3):
///   x(t) = x0 + t * fl(x1 - x0): errors u*2M + u*2M + u*(M + 4uM)  <= 5uM (+O(u^2)).
///   w * x(t), |w| <= 1 exact:    5uM + u*M                          <= 6uM.
///   four terms (|term| <= M) summed pairwise / in sequence: partial sums <= 2M, 2M|3M, 4M,
///   rounding <= 9uM; propagated term errors <= 4 * 6uM = 24uM.       total <= 33uM.
/// We use 64uM, and an absolute floor for gradual underflow. Exact inputs (e.g. the rational
/// sample queries rounded to double) are not part of the bound: the query is the double input.
double errorBound(double max_abs) {
    constexpr double u = std::numeric_limits<double>::epsilon() / 2;
    return 64.0 * u * max_abs + 64.0 * std::numeric_limits<double>::denorm_min();
}

/// True when n . F > 0 (or < 0) on the whole box, with the min separation: then the box holds
/// no contact. Each point of the box is a convex combination of its corners (weights products
/// of s and 1 - s per variable) and F is multilinear, so F(box) lies in the convex hull of the 8
/// corner values (the convex-hull property of the tensor-product Bernstein form) and
/// min_c n . F_c bounds n . F from below on the box, for any direction n. Rounding: the computed
/// corner differs from the exact one by <= err per axis, and the three-term dot product adds
/// <= gamma_3 sum |n_a| |F_a| (Higham §3.1), both in dir_err; a point within the min separation
/// (max norm) has |n . F| <= gap sum |n_a|.
/// n is first scaled to max |n_a| ~ 1 (any direction is as valid as n): a raw plane normal is
/// quadratic in the coordinates, and its products with F would overflow (to +-inf, NaN) at
/// coordinates near 1e100 while the bound stayed finite. Scaled, |n . F| <= 3 (4 max_abs + err),
/// finite for every accepted input (finiteInput).
bool excludedAlong(const Query& q, const double vals[8][3], const double raw[3]) {
    const double scale = std::max({std::abs(raw[0]), std::abs(raw[1]), std::abs(raw[2])});
    if (!(scale > 0) || !std::isfinite(scale)) return false;  // no direction
    const double inv = 1.0 / scale;
    const double n[3] = {raw[0] * inv, raw[1] * inv, raw[2] * inv};
    double lo = std::numeric_limits<double>::infinity();
    double hi = -lo;
    for (int c = 0; c < 8; ++c) {
        const double s = n[0] * vals[c][0] + n[1] * vals[c][1] + n[2] * vals[c][2];
        lo = std::min(lo, s);
        hi = std::max(hi, s);
    }
    // (1 + 8u) covers the rounding of this sum of non-negative terms.
    constexpr double kUp = 1.0 + 8.0 * (std::numeric_limits<double>::epsilon() / 2);
    const double bound = kUp * (std::abs(n[0]) * (q.dir_err[0] + q.gap) +
                                std::abs(n[1]) * (q.dir_err[1] + q.gap) +
                                std::abs(n[2]) * (q.dir_err[2] + q.gap));
    return lo > bound || hi < -bound;
}

/// The normal of the primitives' common plane at time t: the face's normal (vertex-face) or
/// the cross product of the edges (edge-edge). Along it F is, at that t, independent of u and
/// v, so a vertex or an edge sliding near and parallel to the other primitive is excluded by
/// one projection instead of a fine grid of (u, v) cells. Zero for degenerate primitives
/// (the projection then excludes nothing, which is safe).
void planeNormal(const Query& q, double t, double n[3]) {
    double p[4][3];
    for (int i = 0; i < 4; ++i) {
        for (int a = 0; a < 3; ++a) p[i][a] = q.x0[i][a] + t * q.dx[i][a];
    }
    double e[3], f[3];
    for (int a = 0; a < 3; ++a) {
        if (q.pair == PrimitivePair::VertexFace) {
            e[a] = p[2][a] - p[1][a];
            f[a] = p[3][a] - p[1][a];
        } else {
            e[a] = p[1][a] - p[0][a];
            f[a] = p[3][a] - p[2][a];
        }
    }
    n[0] = e[1] * f[2] - e[2] * f[1];
    n[1] = e[2] * f[0] - e[0] * f[2];
    n[2] = e[0] * f[1] - e[1] * f[0];
}

/// True when the box's image provably misses the origin inflated by the min separation:
/// first per axis (the exact range of F per axis lies within [min - err, max + err] of the
/// computed corners), then along the primitives' plane normal at the box's mid time, then
/// along the mean of the corner values (the direction from the origin towards a small image).
/// `width` gets the largest computed image width over the axes.
bool excludedBox(const Query& q, const ParamBox& box, const double vals[8][3], double& width) {
    width = 0;
    double mean[3];
    for (int a = 0; a < 3; ++a) {
        double lo = vals[0][a];
        double hi = vals[0][a];
        double sum = vals[0][a];
        for (int c = 1; c < 8; ++c) {
            lo = std::min(lo, vals[c][a]);
            hi = std::max(hi, vals[c][a]);
            sum += vals[c][a];
        }
        if (lo - q.err[a] > q.gap || hi + q.err[a] < -q.gap) return true;
        width = std::max(width, hi - lo);
        mean[a] = sum;
    }
    double n[3];
    planeNormal(q, 0.5 * (box.t_lo + box.t_hi), n);
    return excludedAlong(q, vals, n) || excludedAlong(q, vals, mean);
}

/// True when every point of the box is provably within the min separation (max norm) of
/// contact: the whole image, error included, lies in [-gap, gap] on every axis. Never true
/// for gap = 0 (the error bound is positive), so it only resolves contact patches.
bool certainBox(const Query& q, const double vals[8][3]) {
    for (int a = 0; a < 3; ++a) {
        for (int c = 0; c < 8; ++c) {
            if (std::abs(vals[c][a]) + q.err[a] > q.gap) return false;
        }
    }
    return true;
}

Query makeQuery(PrimitivePair pair, const std::array<Vec3, 4>& t0, const std::array<Vec3, 4>& t1,
                const CcdSettings& settings) {
    Query q;
    q.pair = pair;
    double max_abs[3] = {0, 0, 0};
    double lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
        lo[a] = std::numeric_limits<double>::infinity();
        hi[a] = -lo[a];
    }
    for (int i = 0; i < 4; ++i) {
        for (int a = 0; a < 3; ++a) {
            const double x0 = static_cast<double>(t0[i][a]);
            const double x1 = static_cast<double>(t1[i][a]);
            q.x0[i][a] = x0;
            q.dx[i][a] = x1 - x0;
            max_abs[a] = std::max({max_abs[a], std::abs(x0), std::abs(x1)});
            lo[a] = std::min({lo[a], x0, x1});
            hi[a] = std::max({hi[a], x0, x1});
        }
    }
    double size = 0;
    double max_err = 0;
    constexpr double u = std::numeric_limits<double>::epsilon() / 2;
    for (int a = 0; a < 3; ++a) {
        q.err[a] = errorBound(max_abs[a]);
        // |computed F_a| <= 4 max_abs + err (weights of magnitude <= 1, at most 3 of them on
        // the face side), and gamma_3 <= 4u.
        q.dir_err[a] = q.err[a] + 4.0 * u * (4.0 * max_abs[a] + q.err[a]);
        max_err = std::max(max_err, q.err[a]);
        size = std::max(size, hi[a] - lo[a]);
    }
    q.gap = static_cast<double>(std::max<Real>(settings.min_separation, 0));
    // The acceptance width must stay reachable above the rounding noise of F.
    q.accept = std::max(static_cast<double>(settings.tolerance) * size, 4.0 * max_err);
    return q;
}

bool finiteInput(const std::array<Vec3, 4>& t0, const std::array<Vec3, 4>& t1) {
    constexpr double kHuge = 1e150;  // keeps every product and sum in cornerValues finite
    for (int i = 0; i < 4; ++i) {
        if (!t0[i].allFinite() || !t1[i].allFinite()) return false;
        if (t0[i].cwiseAbs().maxCoeff() > kHuge || t1[i].cwiseAbs().maxCoeff() > kHuge) {
            return false;
        }
    }
    return true;
}

// Earliest start of a parameter box proven to be all contact (only with min_separation > 0:
// contact patches), and its witness; t above 1: none yet.
struct Certain {
    double t = 2;
    double u = 0;
    double v = 0;
};

void pushBox(std::vector<ParamBox>& heap, const ParamBox& box) {
    heap.push_back(box);
    std::push_heap(heap.begin(), heap.end(), LaterBox{});
}

// Which variable (0 t, 1 u, 2 v) to split: the one that moves F most on this box (the largest
// corner difference along it) among those whose interval is still wider than kMinWidth; -1
// when none is. `can_split` says which are.
int splitDimension(const ParamBox& box, const double (&vals)[8][3], bool (&can_split)[3]) {
    double effect[3] = {0, 0, 0};  // t, u, v
    for (int c = 0; c < 8; ++c) {
        for (int a = 0; a < 3; ++a) {
            for (int d = 0; d < 3; ++d) {
                const int bit = 4 >> d;  // corner-index bit of t, u, v
                if ((c & bit) != 0) continue;
                effect[d] = std::max(effect[d], std::abs(vals[c | bit][a] - vals[c][a]));
            }
        }
    }
    can_split[0] = box.t_hi - box.t_lo > kMinWidth;
    can_split[1] = box.u_hi - box.u_lo > kMinWidth;
    can_split[2] = box.v_hi - box.v_lo > kMinWidth;
    int dim = -1;
    for (int d = 0; d < 3; ++d) {
        if (can_split[d] && (dim < 0 || effect[d] > effect[dim])) dim = d;
    }
    return dim;
}

// Look-ahead in t (the variable the answer is about): if one half of the t interval is provably
// empty, keep only the other half at the current u, v resolution (true: the box is dealt with).
// This bisects t while u, v stay coarse, instead of refining u, v cells along a curve or patch
// of contacts (parallel edges, face-parallel motion) where every cell would then need its own
// proof that the early half is empty. A late half that is all contact moves `certain` earlier.
bool lookAheadInT(const Query& q, const ParamBox& box, Certain& certain,
                  std::vector<ParamBox>& heap) {
    const double mid = 0.5 * (box.t_lo + box.t_hi);
    ParamBox early = box;
    ParamBox late = box;
    early.t_hi = late.t_lo = mid;
    early.depth = late.depth = box.depth + 1;
    double child_vals[8][3];
    double child_width = 0;
    cornerValues(q, early, child_vals);
    const bool early_out = excludedBox(q, early, child_vals, child_width);
    cornerValues(q, late, child_vals);
    bool late_out = excludedBox(q, late, child_vals, child_width);
    if (!late_out && certainBox(q, child_vals)) {
        // The late half is all contact: remember its start, drop it.
        if (mid < certain.t) {
            certain.t = mid;
            certain.u = 0.5 * (box.u_lo + box.u_hi);
            certain.v = 0.5 * (box.v_lo + box.v_hi);
        }
        late_out = true;
    }
    if (!early_out && !late_out) return false;
    if (!early_out) pushBox(heap, early);
    if (!late_out && late.t_lo < certain.t) pushBox(heap, late);
    return true;
}

// The box halved along `dim`; the later half is dropped when it starts at or after the certain
// contact.
void bisect(const ParamBox& box, int dim, double certain_t, std::vector<ParamBox>& heap) {
    ParamBox a = box;
    ParamBox b = box;
    a.depth = b.depth = box.depth + 1;
    if (dim == 0) {
        const double mid = 0.5 * (box.t_lo + box.t_hi);
        a.t_hi = b.t_lo = mid;
    } else if (dim == 1) {
        const double mid = 0.5 * (box.u_lo + box.u_hi);
        a.u_hi = b.u_lo = mid;
    } else {
        const double mid = 0.5 * (box.v_lo + box.v_hi);
        a.v_hi = b.v_lo = mid;
    }
    pushBox(heap, a);
    if (b.t_lo < certain_t) pushBox(heap, b);
}

CcdOutput inclusionCcd(PrimitivePair pair, const std::array<Vec3, 4>& t0,
                       const std::array<Vec3, 4>& t1, const CcdSettings& settings) {
    CcdOutput out;
    if (!finiteInput(t0, t1)) {
        out.state = CcdState::Failed;
        out.t = out.t_upper = 0;
        return out;
    }
    const Query q = makeQuery(pair, t0, t1, settings);

    // Reused across queries on this thread: no heap allocation per query once warm.
    thread_local std::vector<ParamBox> heap;
    heap.clear();
    heap.push_back(ParamBox{0, 1, 0, 1, 0, 1, 0});
    const LaterBox later;
    const int max_boxes = std::max(settings.max_boxes, 1);
    const double t_tol = std::max(static_cast<double>(settings.time_tolerance), 0.0);
    // Earliest start of a parameter box proven to be all contact (only with min_separation > 0:
    // contact patches), and its witness. Above 1: none yet.
    Certain certain;

    double vals[8][3];
    while (!heap.empty()) {
        std::pop_heap(heap.begin(), heap.end(), later);
        ParamBox box = heap.back();
        heap.pop_back();
        // A contact is certain at certain.t and none exists before box.t_lo (every box left
        // starts later): the first contact is bracketed in [box.t_lo, certain.t].
        if (certain.t - box.t_lo <= t_tol) {
            out.state = CcdState::Hit;
            out.t = box.t_lo;
            out.t_upper = certain.t;
            out.u = certain.u;
            out.v = certain.v;
            return out;
        }
        box.t_hi = std::min(box.t_hi, certain.t);  // nothing later can lower the answer
        if (out.iterations >= max_boxes) {
            // Every unresolved box starts at or after box.t_lo: no contact before it.
            out.state = CcdState::Failed;
            out.t = out.t_upper = box.t_lo;
            return out;
        }
        ++out.iterations;

        // Vertex-face: the triangle is u, v >= 0, u + v <= 1. fl(u_lo + v_lo) > 1 implies the
        // exact sum > 1 (rounding is monotone), so this box misses the triangle.
        if (pair == PrimitivePair::VertexFace && box.u_lo + box.v_lo > 1.0) continue;

        cornerValues(q, box, vals);
        double width = 0;
        if (excludedBox(q, box, vals, width)) continue;
        if (certainBox(q, vals)) {
            // Every point of the box is a contact, the earliest at t_lo, and nothing before it.
            out.state = CcdState::Hit;
            out.t = out.t_upper = box.t_lo;
            out.u = 0.5 * (box.u_lo + box.u_hi);
            out.v = 0.5 * (box.v_lo + box.v_hi);
            return out;
        }

        bool can_split[3];
        const int dim = splitDimension(box, vals, can_split);
        if (width <= q.accept || dim < 0) {
            // Image within the acceptance width of the origin (or the box cannot shrink):
            // report this box. Its t_lo is <= every queued t_lo, hence <= the first root.
            out.state = CcdState::Hit;
            out.t = box.t_lo;
            out.t_upper = box.t_hi;
            out.u = 0.5 * (box.u_lo + box.u_hi);
            out.v = 0.5 * (box.v_lo + box.v_hi);
            return out;
        }
        if (can_split[0] && lookAheadInT(q, box, certain, heap)) continue;
        bisect(box, dim, certain.t, heap);
    }
    if (certain.t <= 1) {
        // Everything before certain.t is excluded and a contact is certain there.
        out.state = CcdState::Hit;
        out.t = out.t_upper = certain.t;
        out.u = certain.u;
        out.v = certain.v;
        return out;
    }
    out.state = CcdState::Separated;
    out.t = out.t_upper = 1;
    return out;
}

}  // namespace

CcdOutput vertexFaceCcd(const VertexFaceCcdInput& input, const CcdSettings& settings) {
    return inclusionCcd(PrimitivePair::VertexFace, input.t0, input.t1, settings);
}

CcdOutput edgeEdgeCcd(const EdgeEdgeCcdInput& input, const CcdSettings& settings) {
    return inclusionCcd(PrimitivePair::EdgeEdge, input.t0, input.t1, settings);
}

}  // namespace collision
