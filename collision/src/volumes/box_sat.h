// collision/src/volumes/box_sat.h -- the separating-axis test of two oriented boxes, in its two
// forms: boolean and conservative (testSat15: Obb::overlaps in the broad phases, the OBB and RSS
// node volumes of the mesh hierarchies) and measuring (measureBoxSat: the box-box pair of both
// collide() and contact(), which decide from the same measure). Private to collision.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#if defined(__SSE__)
#include <xmmintrin.h>
#endif
#if defined(__SSE2__) && !defined(CDLAB_USE_FLOAT)
#include <emmintrin.h>
#endif

#include "collision/assert.h"
#include "collision/math.h"

namespace collision {

/// Separating-axis test of two boxes (Gottschalk, Lin, Manocha 1996 §4; RTCD 4.4.1) in A's box
/// frame: `a`, `b` half extents, `rot` B's axes in A's box frame, `t` B's centre there. With
/// kSwept, both boxes are additionally swept by spheres of total radius `radius_sum` (RSS): on
/// every axis L the projection grows by radius_sum |L|. Fifteen axes only: for swept volumes this
/// is conservative (the rounded edges are treated as the enclosing box edges).
template <bool kSwept>
[[gnu::always_inline]] inline bool testSat15(const Vec3& a, const Mat3& rot, const Vec3& t,
                                             const Vec3& b, Real tol, Real radius_sum) {
    // |R| + eps keeps near-parallel edge pairs (cross product ~ 0) from false separations.
    const Mat3 abs_rot = rot.cwiseAbs().array() + Real(16) * kEpsilon;
    const Real face_slack = tol + (kSwept ? radius_sum : Real(0));
    for (int i = 0; i < 3; ++i) {
        if (std::abs(t[i]) > a[i] + abs_rot.row(i).dot(b) + face_slack) return false;
    }
    for (int j = 0; j < 3; ++j) {
        if (std::abs(t.dot(rot.col(j))) > abs_rot.col(j).dot(a) + b[j] + face_slack) return false;
    }
    for (int i = 0; i < 3; ++i) {
        const int i1 = (i + 1) % 3;
        const int i2 = (i + 2) % 3;
        for (int j = 0; j < 3; ++j) {
            const int j1 = (j + 1) % 3;
            const int j2 = (j + 2) % 3;
            Real slack = tol;
            if constexpr (kSwept) {
                // |A_i x B_j| = |e_i x rot.col(j)| = sqrt(R_i1j^2 + R_i2j^2). Not sqrt(1 - R_ij^2):
                // that rounds to 0 for near-parallel axes and falsely separates (found on a cube
                // whose node axes were 1.7e-7 off the grid).
                slack +=
                    radius_sum * (std::sqrt(rot(i1, j) * rot(i1, j) + rot(i2, j) * rot(i2, j)) +
                                  Real(16) * kEpsilon);
            }
            const Real ra = a[i1] * abs_rot(i2, j) + a[i2] * abs_rot(i1, j);
            const Real rb = b[j1] * abs_rot(i, j2) + b[j2] * abs_rot(i, j1);
            const Real dist = std::abs(t[i2] * rot(i1, j) - t[i1] * rot(i2, j));
            if (dist > ra + rb + slack) return false;
        }
    }
    return true;
}

/// The 15 axes of two boxes measured (RTCD 4.4.1; Gottschalk et al. 1996 §4): on each unit axis
/// L the separation |t.L| - ra - rb (positive: a gap along L; the largest over the axes is, for
/// boxes, minus the exact penetration depth, or a lower bound on the distance), and a first-order
/// rounding bound err = 8 eps (|t.L| + ra + rb) on each. Edge axes are normalised before
/// projecting; only those of exactly parallel edges (|e_a x e_b|^2 below the smallest normal
/// number) are skipped, since the face axes cover them. Nearly parallel edges are not skipped: at
/// an angle theta the face axes miss the edge axis's gap by up to |e| sin(theta) (two cube ridges
/// of half size s, theta = 1e-7, 1e-7 s apart were Penetrating while a 1e-6 cut-off skipped their
/// axis; tests/collision/extremes_test.cpp).
// Calls visit(dist, ra, rb, axis, id) for each measured axis (unit L, A's frame): face axes of A
// (id 0..2), face axes of B (3..5), then the edge axes A_i x B_j (6 + 3 i + j), with dist = |t.L|
// and ra, rb the boxes' projection radii.
// One measured axis: dist = |t.L|, ra and rb the boxes' projection radii, on unit L (A's frame).
struct BoxSatAxis {
    Real dist;
    Real ra;
    Real rb;
    Vec3 axis;
};

inline BoxSatAxis boxSatFaceAxisA(const Vec3& ea, const Mat3& rot, const Vec3& t, const Vec3& eb,
                                  int i) {
    return {std::abs(t[i]), ea[i], eb.dot(rot.row(i).transpose().cwiseAbs()), Vec3::Unit(i)};
}

inline BoxSatAxis boxSatFaceAxisB(const Vec3& ea, const Mat3& rot, const Vec3& t, const Vec3& eb,
                                  int j) {
    const Vec3 axis = rot.col(j);
    return {std::abs(t.dot(axis)), ea.dot(axis.cwiseAbs()), eb[j], axis};
}

// The edge axis A_i x B_j normalised; false for exactly parallel edges (|A_i x B_j|^2 below the
// smallest normal number), which the face axes cover.
inline bool boxSatEdgeAxis(const Vec3& ea, const Mat3& rot, const Vec3& t, const Vec3& eb, int i,
                           int j, BoxSatAxis& out) {
    constexpr Real kParallelCross = std::numeric_limits<Real>::min();
    const Vec3 axis = Vec3::Unit(i).cross(rot.col(j));
    const Real len2 = axis.squaredNorm();
    if (!(len2 >= kParallelCross)) return false;
    const Vec3 unit = axis / std::sqrt(len2);
    out = {std::abs(t.dot(unit)), ea.dot(unit.cwiseAbs()),
           eb.dot((rot.transpose() * unit).cwiseAbs()), unit};
    return true;
}

template <class Visit>
inline void forEachBoxSatAxis(const Vec3& ea, const Mat3& rot, const Vec3& t, const Vec3& eb,
                              Visit&& visit) {
    for (int i = 0; i < 3; ++i) {
        const BoxSatAxis a = boxSatFaceAxisA(ea, rot, t, eb, i);
        visit(a.dist, a.ra, a.rb, a.axis, i);
    }
    for (int j = 0; j < 3; ++j) {
        const BoxSatAxis a = boxSatFaceAxisB(ea, rot, t, eb, j);
        visit(a.dist, a.ra, a.rb, a.axis, 3 + j);
    }
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            BoxSatAxis a;
            if (boxSatEdgeAxis(ea, rot, t, eb, i, j, a)) {
                visit(a.dist, a.ra, a.rb, a.axis, 6 + 3 * i + j);
            }
        }
    }
}

struct BoxSatMeasure {
    static constexpr int kMaxAxes = 15;
    // Only the first axis_count entries are set (no zeroing on the hot path).
    std::array<Real, kMaxAxes> sep;  ///< per measured axis: |t.L| - ra - rb
    std::array<Real, kMaxAxes> mag;  ///< |t.L| + ra + rb: that axis's err is 8 eps mag
    int axis_count = 0;
    Real max_sep = -std::numeric_limits<Real>::infinity();   ///< max of face_sep, edge_sep
    Real face_sep = -std::numeric_limits<Real>::infinity();  ///< best of the 6 face axes
    int face_box = 0;                                        ///< 0: a face of A, 1: of B
    int face_axis = 0;
    Real edge_sep = -std::numeric_limits<Real>::infinity();  ///< best of the 9 edge axes
    int edge_a = 0;                                          ///< A's edge direction (axis index)
    int edge_b = 0;                                          ///< B's edge direction
    Vec3 edge_axis = Vec3::Zero();                           ///< unit, A's frame
    /// At least every axis's err, twice over: 16 eps (|t|_1 + |ea|_1 + |eb|_1), since
    /// |t.L| + ra + rb <= |t| + |ea| + |eb| for |L| = 1 (up to rounding); for the decisions that
    /// need no per-axis bound.
    Real err_bound = 0;

    /// False for measureBoxSatBest's result: sep, mag and axis_count are not filled.
    bool per_axis = true;

    /// Max over the axes of sep - err: the largest gap the axes prove.
    Real gapLo() const { return gap(-1); }
    /// Max over the axes of sep + err: below -tolerance, every axis proves the overlap.
    Real gapHi() const { return gap(1); }

private:
    Real gap(Real sign) const {
        CDLAB_ASSERT(per_axis, "BoxSatMeasure::gap on a best-axes measure");
        Real g = -std::numeric_limits<Real>::infinity();
        for (std::size_t k = 0; k < static_cast<std::size_t>(axis_count); ++k) {
            g = std::max(g, sep[k] + sign * (Real(8) * kEpsilon * mag[k]));
        }
        return g;
    }
};

/// Measures the 15 axes in A's box frame: `ea`, `eb` half extents, `rot` B's axes in A's frame,
/// `t` B's centre there.
inline BoxSatMeasure measureBoxSat(const Vec3& ea, const Mat3& rot, const Vec3& t, const Vec3& eb) {
    BoxSatMeasure m;
    forEachBoxSatAxis(ea, rot, t, eb, [&m](Real dist, Real ra, Real rb, const Vec3& axis, int id) {
        const Real sep = dist - ra - rb;
        m.sep[static_cast<std::size_t>(m.axis_count)] = sep;
        m.mag[static_cast<std::size_t>(m.axis_count)] = dist + ra + rb;
        ++m.axis_count;
        if (id < 6) {
            if (sep > m.face_sep) {
                m.face_sep = sep;
                m.face_box = id < 3 ? 0 : 1;
                m.face_axis = id % 3;
            }
        } else if (sep > m.edge_sep) {
            m.edge_sep = sep;
            m.edge_a = (id - 6) / 3;
            m.edge_b = (id - 6) % 3;
            m.edge_axis = axis;
        }
    });
    m.max_sep = std::max(m.face_sep, m.edge_sep);
    m.err_bound = Real(16) * kEpsilon *
                  (t.lpNorm<1>() + ea.lpNorm<1>() + eb.lpNorm<1>());  // 1-norms >= 2-norms
    return m;
}

/// 1 / sqrt of 12 floats (> 0, 16-byte aligned), to a relative error below 1.5 * 2^-12: SSE's
/// rsqrtps (in the x86-64 baseline), else exact.
inline void boxSatRsqrt(const float* in, float* out) {
#if defined(__SSE__)
    // The lanes are gathered one by one, not loaded as a vector: the caller has just written
    // them one by one, and a vector load of scalar stores waits for them to retire.
    for (int k = 0; k < 12; k += 4) {
        const __m128 v = _mm_setr_ps(in[k], in[k + 1], in[k + 2], in[k + 3]);
        _mm_store_ps(out + k, _mm_rsqrt_ps(v));
    }
#else
    for (int k = 0; k < 12; ++k) out[k] = 1.0f / std::sqrt(in[k]);
#endif
}

// The estimates of the nine edge axes A_i x B_j (k = 3 i + j) for measureBoxSatBest: hi[k] an
// upper bound on edge k's separation (+inf for an edge closer to parallel than
// kBoxSatNearParallel2, which is always measured), and over the other edges, in order of k,
// cut = max of the lower bounds and max_hi = max of hi. Unnormalised (Gottschalk, Lin, Manocha
// 1996, "OBBTree" §4: with L = A_i x B_j, t.L, ra and rb are two products each of entries of R
// and |R|), scaled by an approximate 1 / |L| (SSE rsqrtps, relative error below 1.5 * 2^-12,
// allowed for as kBoxSatRsqrtRelative).
inline constexpr Real kBoxSatNearParallel2 = Real(1e-8);
inline constexpr Real kBoxSatRsqrtRelative = Real(1e-3);

#if defined(__SSE2__) && !defined(CDLAB_USE_FLOAT)
[[gnu::always_inline]] inline __m128d boxSatAbs(__m128d x) {
    return _mm_andnot_pd(_mm_set1_pd(-0.0), x);
}

// Two edges in the two lanes, each with the scalar form's operations in its order, so every
// lane holds the scalar form's bits. r1, r2 are R(i1, j), R(i2, j) and q1, q2 their absolute
// values; a_j1, a_j2 are |R(i, j1)|, |R(i, j2)|; the rest the entries of t, ea, eb at those
// indices (i1, i2 and j1, j2 follow i and j cyclically). Writes |L|^2 and the unnormalised
// separation |t.L| - ra - rb.
[[gnu::always_inline]] inline void boxSatEdgeLanes(__m128d r1, __m128d r2, __m128d q1, __m128d q2,
                                                   __m128d t_i1, __m128d t_i2, __m128d ea_i1,
                                                   __m128d ea_i2, __m128d eb_j1, __m128d eb_j2,
                                                   __m128d a_j1, __m128d a_j2, __m128d& len2,
                                                   __m128d& sep) {
    len2 = _mm_add_pd(_mm_mul_pd(r1, r1), _mm_mul_pd(r2, r2));
    const __m128d dist = boxSatAbs(_mm_sub_pd(_mm_mul_pd(t_i2, r1), _mm_mul_pd(t_i1, r2)));
    const __m128d ra = _mm_add_pd(_mm_mul_pd(ea_i1, q2), _mm_mul_pd(ea_i2, q1));
    const __m128d rb = _mm_add_pd(_mm_mul_pd(eb_j1, a_j2), _mm_mul_pd(eb_j2, a_j1));
    sep = _mm_sub_pd(_mm_sub_pd(dist, ra), rb);
}

// hi and lo of two edges from |L|^2, the unnormalised separation and ~1 / |L|, stored at
// hi_out, lo_out: +inf and -inf for an edge that is not measurable.
[[gnu::always_inline]] inline void boxSatEdgeBounds(__m128d len2, __m128d sep, __m128d inv_len,
                                                    double* hi_out, double* lo_out) {
    const __m128d e = _mm_mul_pd(sep, inv_len);
    const __m128d slack = _mm_mul_pd(_mm_set1_pd(kBoxSatRsqrtRelative), boxSatAbs(e));
    const __m128d measurable = _mm_cmpge_pd(len2, _mm_set1_pd(kBoxSatNearParallel2));
    const __m128d inf = _mm_set1_pd(std::numeric_limits<Real>::infinity());
    _mm_storeu_pd(hi_out, _mm_or_pd(_mm_and_pd(measurable, _mm_add_pd(e, slack)),
                                    _mm_andnot_pd(measurable, inf)));
    _mm_storeu_pd(lo_out, _mm_or_pd(_mm_and_pd(measurable, _mm_sub_pd(e, slack)),
                                    _mm_andnot_pd(measurable, _mm_xor_pd(inf, _mm_set1_pd(-0.0)))));
}

// Four edges (two pairs) at once: one rsqrtps on their |L|^2 rounded to float.
[[gnu::always_inline]] inline void boxSatEdgeBounds4(__m128d len2_a, __m128d sep_a,
                                                     __m128d len2_b, __m128d sep_b,
                                                     double* hi_out, double* lo_out) {
    const __m128 inv = _mm_rsqrt_ps(_mm_movelh_ps(_mm_cvtpd_ps(len2_a), _mm_cvtpd_ps(len2_b)));
    boxSatEdgeBounds(len2_a, sep_a, _mm_cvtps_pd(inv), hi_out, lo_out);
    boxSatEdgeBounds(len2_b, sep_b, _mm_cvtps_pd(_mm_movehl_ps(inv, inv)), hi_out + 2,
                     lo_out + 2);
}

// The lanes in pairs: (i = 0, 1) for each j, then (i = 2; j = 0, 1), then (i = 2, j = 2) in the
// low lane. The maxima are taken one edge at a time in order of k, as the scalar form does.
inline void boxSatEdgeEstimates(const Vec3& ea, const Mat3& rot, const Vec3& t, const Vec3& eb,
                                std::array<Real, 9>& hi, Real& cut, Real& max_hi) {
    const double* d = rot.data();  // column-major: R(r, c) = d[r + 3 c]
    const __m128d t01 = _mm_loadu_pd(t.data());
    const __m128d t12 = _mm_loadu_pd(t.data() + 1);
    const __m128d t20 = _mm_shuffle_pd(t12, t01, 1);
    const __m128d ea01 = _mm_loadu_pd(ea.data());
    const __m128d ea12 = _mm_loadu_pd(ea.data() + 1);
    const __m128d ea20 = _mm_shuffle_pd(ea12, ea01, 1);
    // Rows 0, 1 and rows 1, 2 of each column, and their absolute values. Plain arrays:
    // std::array drops __m128d's alignment attribute.
    __m128d c01[3];
    __m128d c12[3];
    __m128d abs01[3];
    __m128d abs12[3];
    for (int j = 0; j < 3; ++j) {
        c01[j] = _mm_loadu_pd(d + 3 * j);
        c12[j] = _mm_loadu_pd(d + 3 * j + 1);
        abs01[j] = boxSatAbs(c01[j]);
        abs12[j] = boxSatAbs(c12[j]);
    }
    // Edge k's bounds at lane kLane[k] of these (lane l of pair p is 2 p + l; the last high lane
    // is not an edge).
    std::array<Real, 10> hi_lanes;
    std::array<Real, 10> lo_lanes;
    constexpr std::array<std::size_t, 9> kLane{0, 2, 4, 1, 3, 5, 6, 7, 8};
    // i = 0, 1 (i1 = 1, 2; i2 = 2, 0) with column j: r1 = (R(1, j), R(2, j)), r2 = (R(2, j),
    // R(0, j)); R(i, j1) and R(i, j2) are rows 0 and 1 of columns j1 and j2.
    __m128d len2[3];
    __m128d sep[3];
    for (int j = 0; j < 3; ++j) {
        const int j1 = (j + 1) % 3;
        const int j2 = (j + 2) % 3;
        boxSatEdgeLanes(c12[j], _mm_shuffle_pd(c12[j], c01[j], 1), abs12[j],
                        _mm_shuffle_pd(abs12[j], abs01[j], 1), t12, t20, ea12, ea20,
                        _mm_set1_pd(eb[j1]), _mm_set1_pd(eb[j2]), abs01[j1], abs01[j2], len2[j],
                        sep[j]);
    }
    boxSatEdgeBounds4(len2[0], sep[0], len2[1], sep[1], hi_lanes.data(), lo_lanes.data());
    // i = 2 (i1 = 0, i2 = 1), j = 0, 1 (j1 = 1, 2; j2 = 2, 0): r1 = (R(0, 0), R(0, 1)), r2 =
    // (R(1, 0), R(1, 1)).
    const __m128d t0 = _mm_set1_pd(t[0]);
    const __m128d t1 = _mm_set1_pd(t[1]);
    const __m128d ea0 = _mm_set1_pd(ea[0]);
    const __m128d ea1 = _mm_set1_pd(ea[1]);
    const __m128d eb01 = _mm_loadu_pd(eb.data());
    const __m128d eb12 = _mm_loadu_pd(eb.data() + 1);
    const __m128d eb20 = _mm_shuffle_pd(eb12, eb01, 1);
    __m128d len2_q;
    __m128d sep_q;
    boxSatEdgeLanes(_mm_unpacklo_pd(c01[0], c01[1]), _mm_unpackhi_pd(c01[0], c01[1]),
                    _mm_unpacklo_pd(abs01[0], abs01[1]), _mm_unpackhi_pd(abs01[0], abs01[1]), t0,
                    t1, ea0, ea1, eb12, eb20, _mm_unpackhi_pd(abs12[1], abs12[2]),
                    _mm_unpackhi_pd(abs12[2], abs12[0]), len2_q, sep_q);
    boxSatEdgeBounds4(len2[2], sep[2], len2_q, sep_q, hi_lanes.data() + 4, lo_lanes.data() + 4);
    // i = 2, j = 2 (j1 = 0, j2 = 1) in the low lane: r1 = R(0, 2), r2 = R(1, 2).
    __m128d len2_z;
    __m128d sep_z;
    boxSatEdgeLanes(c01[2], _mm_unpackhi_pd(c01[2], c01[2]), abs01[2],
                    _mm_unpackhi_pd(abs01[2], abs01[2]), t0, t1, ea0, ea1, eb01, eb12,
                    _mm_unpackhi_pd(abs12[0], abs12[0]), _mm_unpackhi_pd(abs12[1], abs12[1]),
                    len2_z, sep_z);
    const __m128 inv_z = _mm_rsqrt_ps(_mm_cvtpd_ps(len2_z));
    boxSatEdgeBounds(len2_z, sep_z, _mm_cvtps_pd(inv_z), hi_lanes.data() + 8,
                     lo_lanes.data() + 8);
    for (std::size_t k = 0; k < 9; ++k) {
        hi[k] = hi_lanes[kLane[k]];
        cut = std::max(cut, lo_lanes[kLane[k]]);
        max_hi = std::max(max_hi, hi[k]);
    }
}
#else
inline void boxSatEdgeEstimates(const Vec3& ea, const Mat3& rot, const Vec3& t, const Vec3& eb,
                                std::array<Real, 9>& hi, Real& cut, Real& max_hi) {
    alignas(16) std::array<float, 12> len2f{};
    std::array<Real, 9> unnormalised;
    std::array<bool, 9> measurable;
    // Edge k = 3 i + j: i1, i2 follow i and j1, j2 follow j cyclically.
    constexpr std::array<int, 9> kI{0, 0, 0, 1, 1, 1, 2, 2, 2};
    constexpr std::array<int, 9> kJ{0, 1, 2, 0, 1, 2, 0, 1, 2};
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC unroll 9
#endif
    for (std::size_t k = 0; k < 9; ++k) {
        const int i = kI[k];
        const int j = kJ[k];
        const int i1 = (i + 1) % 3;
        const int i2 = (i + 2) % 3;
        const int j1 = (j + 1) % 3;
        const int j2 = (j + 2) % 3;
        const Real r1 = rot(i1, j);
        const Real r2 = rot(i2, j);
        const Real len2 = r1 * r1 + r2 * r2;
        const Real dist = std::abs(t[i2] * r1 - t[i1] * r2);
        const Real ra = ea[i1] * std::abs(r2) + ea[i2] * std::abs(r1);
        const Real rb = eb[j1] * std::abs(rot(i, j2)) + eb[j2] * std::abs(rot(i, j1));
        unnormalised[k] = dist - ra - rb;
        measurable[k] = len2 >= kBoxSatNearParallel2;  // also false for NaN
        // Not selected: an edge that is not measurable gets hi = +inf and no part in cut below,
        // so its estimate (from rsqrt of a tiny, zero or NaN len2) is never used.
        len2f[k] = static_cast<float>(len2);
    }
    len2f[9] = len2f[10] = len2f[11] = 1.0f;
    alignas(16) std::array<float, 12> inv_len{};
    boxSatRsqrt(len2f.data(), inv_len.data());
    for (std::size_t k = 0; k < 9; ++k) {
        const Real e = unnormalised[k] * static_cast<Real>(inv_len[k]);
        const Real slack = kBoxSatRsqrtRelative * std::abs(e);
        hi[k] = measurable[k] ? e + slack : std::numeric_limits<Real>::infinity();
        if (measurable[k]) cut = std::max(cut, e - slack);
        max_hi = std::max(max_hi, hi[k]);
    }
}
#endif

/// The fields of measureBoxSat(...) that need no per-axis arrays -- face_sep, face_box,
/// face_axis, max_sep, err_bound, and edge_sep, edge_a, edge_b, edge_axis -- bit for bit, with
/// per_axis false; except that when every edge axis is provably below the best face axis the
/// edge fields keep their defaults (edge_sep = -infinity): the measure's edge_sep is then below
/// face_sep too, so max_sep and every choice between a face and an edge axis are the same. The nine edge axes are first estimated without normalising their vectors
/// (Gottschalk, Lin, Manocha 1996, "OBBTree" §4: with L = A_i x B_j, t.L, ra and rb are two
/// products each of entries of R and |R|) and scaled by an approximate 1 / |L|; only the edges
/// whose estimate can be within rounding of the best are measured as measureBoxSat measures
/// them, in the same order with the same tie rule, so the best edge, its separation and its axis
/// are the same numbers. Unnormalised separation / |L| and measureBoxSat's value are both within
/// 8 eps (|t.L| + ra + rb) <= err_bound / 2 of the true separation, and the approximate 1 / |L|
/// is within kBoxSatRsqrtRelative of 1 / |L|, so an edge whose estimate interval lies below
/// another's by more than 2 err_bound is below that edge's measured value (boxSatEdgeEstimates).
///
/// With `stop_above` finite it returns early, the edge fields unset and max_sep only a lower
/// bound on the measure's, once max_sep + err_bound >= stop_above is certain: callers that only
/// act on a clear overlap (max_sep + err_bound < -tolerance) pass -tolerance and fall back to the
/// full measure, so pairs apart or touching pay little for the attempt.
// Not inlined: inlined into box-box contact(), the SSE2 estimates and the caller's state no
// longer fit the registers, and the spills cost more instructions than the call.
[[gnu::noinline]] inline BoxSatMeasure measureBoxSatBest(
    const Vec3& ea, const Mat3& rot, const Vec3& t, const Vec3& eb,
    Real stop_above = std::numeric_limits<Real>::infinity()) {
    BoxSatMeasure m;
    m.per_axis = false;
    // The best face axis by selects, not branches (which axis wins is data, not a pattern the
    // branch predictor can learn); the first of equal separations wins, as in measureBoxSat.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC unroll 6
#endif
    for (int id = 0; id < 6; ++id) {
        const BoxSatAxis a = id < 3 ? boxSatFaceAxisA(ea, rot, t, eb, id)
                                    : boxSatFaceAxisB(ea, rot, t, eb, id - 3);
        const Real sep = a.dist - a.ra - a.rb;
        const bool better = sep > m.face_sep;
        m.face_sep = better ? sep : m.face_sep;
        m.face_box = better ? (id < 3 ? 0 : 1) : m.face_box;
        m.face_axis = better ? id % 3 : m.face_axis;
    }
    m.err_bound = Real(16) * kEpsilon *
                  (t.lpNorm<1>() + ea.lpNorm<1>() + eb.lpNorm<1>());  // 1-norms >= 2-norms
    if (m.face_sep + m.err_bound >= stop_above) {
        m.max_sep = m.face_sep;
        return m;
    }
    // An edge is measured unless its estimate plus the rsqrt error is below the best estimate
    // minus that error by more than 2 err_bound; edges closer to parallel than
    // kBoxSatNearParallel2 are always measured.
    std::array<Real, 9> hi;
    Real cut = -std::numeric_limits<Real>::infinity();
    Real max_hi = -std::numeric_limits<Real>::infinity();
    boxSatEdgeEstimates(ea, rot, t, eb, hi, cut, max_hi);
    // The edge with the best lower estimate measures at least cut - err_bound.
    if (cut >= stop_above) {
        m.max_sep = std::max(m.face_sep, cut - m.err_bound);
        return m;
    }
    // Every edge provably below the best face: no edge is the best axis nor beats the face, and
    // the edge fields stay unset.
    if (max_hi + Real(2) * m.err_bound < m.face_sep) {
        m.max_sep = m.face_sep;
        return m;
    }
    cut -= Real(2) * m.err_bound;
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC unroll 9
#endif
    for (int k = 0; k < 9; ++k) {
        // NaN estimates (non-finite input) are measured too.
        if (hi[static_cast<std::size_t>(k)] < cut) continue;
        BoxSatAxis a;
        if (!boxSatEdgeAxis(ea, rot, t, eb, k / 3, k % 3, a)) continue;
        const Real sep = a.dist - a.ra - a.rb;
        if (sep > m.edge_sep) {
            m.edge_sep = sep;
            m.edge_a = k / 3;
            m.edge_b = k % 3;
            m.edge_axis = a.axis;
        }
    }
    m.max_sep = std::max(m.face_sep, m.edge_sep);
    return m;
}

}  // namespace collision
