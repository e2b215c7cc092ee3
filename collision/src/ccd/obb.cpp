// collision/src/ccd/obb.cpp -- continuous OBB overlap test over a time interval by interval
// arithmetic (Redon, Kheddar, Coquillart 2002): every quantity of the separating-axis test is
// enclosed by an interval valid for all t in [t0, t1], so "separated on every axis bound" holds
// for the whole interval. Invariant: every interval produced here contains the exact value for
// each t in the interval (up to the rounding slack applied at the final comparison).
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "collision/ccd/ccd.h"
#include "collision/volumes/bounding_volumes.h"

namespace collision {

namespace {

struct Interval {
    Real lo = 0;
    Real hi = 0;
};

Interval point(Real x) { return {x, x}; }
Interval operator+(Interval a, Interval b) { return {a.lo + b.lo, a.hi + b.hi}; }
Interval operator-(Interval a, Interval b) { return {a.lo - b.hi, a.hi - b.lo}; }
Interval operator*(Interval a, Interval b) {
    const Real p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
    return {std::min({p[0], p[1], p[2], p[3]}), std::max({p[0], p[1], p[2], p[3]})};
}
Interval abs(Interval a) {
    if (a.lo >= 0) return a;
    if (a.hi <= 0) return {-a.hi, -a.lo};
    return {0, std::max(-a.lo, a.hi)};
}
Real mag(Interval a) { return std::max(std::abs(a.lo), std::abs(a.hi)); }

// cos over [a, b]: the endpoint values, widened to +-1 where a multiple of pi (resp. an odd
// multiple for -1) lies inside.
Interval cosInterval(Real a, Real b) {
    Real lo = std::min(std::cos(a), std::cos(b));
    Real hi = std::max(std::cos(a), std::cos(b));
    const Real k_max = std::ceil(a / kPi);  // smallest k with k pi >= a
    for (Real k = k_max; k * kPi <= b; k += 1) {
        if (std::fmod(std::abs(k), Real(2)) == 0) {
            hi = 1;
        } else {
            lo = -1;
        }
        if (lo == -1 && hi == 1) break;
    }
    return {lo, hi};
}
Interval sinInterval(Real a, Real b) {
    const Interval c = cosInterval(a - kPi / 2, b - kPi / 2);  // sin x = cos(x - pi/2)
    return c;
}

using IVec = std::array<Interval, 3>;
using IMat = std::array<std::array<Interval, 3>, 3>;  // [row][col]

IMat fromMat(const Mat3& m) {
    IMat r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) r[i][j] = point(m(i, j));
    }
    return r;
}

IMat mul(const IMat& a, const IMat& b) {
    IMat r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            Interval s = point(0);
            for (int k = 0; k < 3; ++k) s = s + a[i][k] * b[k][j];
            r[i][j] = s;
        }
    }
    return r;
}

IMat transpose(const IMat& a) {
    IMat r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) r[i][j] = a[j][i];
    }
    return r;
}

IVec mul(const IMat& a, const IVec& v) {
    IVec r;
    for (int i = 0; i < 3; ++i) r[i] = a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2];
    return r;
}

// Rotation by angle in [t0 |w|, t1 |w|] about the unit axis of w, enclosed (Rodrigues:
// R = I + sin(th) K + (1 - cos(th)) K^2, K the cross-product matrix of the unit axis).
IMat rotationInterval(const Vec3& w, Real t0, Real t1) {
    const Real angle = w.norm();
    if (!(angle > 0)) return fromMat(Mat3::Identity());
    const Vec3 u = w / angle;
    Mat3 k;
    k << 0, -u.z(), u.y(), u.z(), 0, -u.x(), -u.y(), u.x(), 0;
    const Mat3 k2 = k * k;
    const Interval s = sinInterval(t0 * angle, t1 * angle);
    const Interval c = cosInterval(t0 * angle, t1 * angle);
    const Interval one_minus_c = point(1) - c;
    IMat r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            r[i][j] = point(i == j ? 1 : 0) + s * point(k(i, j)) + one_minus_c * point(k2(i, j));
        }
    }
    return r;
}

// World orientation of a sweep over [t0, t1]: R(t rotation) R0 R(t spin).
IMat orientationInterval(const Sweep& s, Real t0, Real t1) {
    return mul(mul(rotationInterval(s.rotation, t0, t1), fromMat(s.start.rotation())),
               rotationInterval(s.spin, t0, t1));
}

bool finite(const Sweep& s) {
    return s.start.position.allFinite() && s.start.orientation.coeffs().allFinite() &&
           s.translation.allFinite() && s.rotation.allFinite() && s.spin.allFinite();
}

}  // namespace

bool testObbSweep(const Obb& box_a, const Sweep& sweep_a, const Obb& box_b, const Sweep& sweep_b,
                  Real t0, Real t1) {
    if (!(t0 <= t1) || !std::isfinite(t0) || !std::isfinite(t1) || !finite(sweep_a) ||
        !finite(sweep_b) || !box_a.center.allFinite() || !box_b.center.allFinite()) {
        return true;
    }
    const Interval tt{t0, t1};
    const IMat ra = orientationInterval(sweep_a, t0, t1);
    const IMat rb = orientationInterval(sweep_b, t0, t1);
    // World axes of the boxes (columns) and centres; positions relative to A's start first.
    const IMat axes_a = mul(ra, fromMat(box_a.axes));
    const IMat axes_b = mul(rb, fromMat(box_b.axes));
    const Vec3 offset = sweep_b.start.position - sweep_a.start.position;
    const IVec ca = mul(ra, IVec{point(box_a.center.x()), point(box_a.center.y()),
                                 point(box_a.center.z())});
    const IVec cb = mul(rb, IVec{point(box_b.center.x()), point(box_b.center.y()),
                                 point(box_b.center.z())});
    IVec d;  // c_b(t) - c_a(t)
    for (int i = 0; i < 3; ++i) {
        d[i] = point(offset[i]) + tt * point(sweep_b.translation[i] - sweep_a.translation[i]) +
               cb[i] - ca[i];
    }
    // In A's frame (RTCD 4.4.1): rot = A^T B, t = A^T d.
    const IMat at = transpose(axes_a);
    const IMat rot = mul(at, axes_b);
    const IVec t = mul(at, d);
    IMat abs_rot;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) abs_rot[i][j] = abs(rot[i][j]);
    }
    const Vec3& a = box_a.half_extents;
    const Vec3& b = box_b.half_extents;
    // Rounding slack: the interval operations are not directed-rounded.
    Real size = a.sum() + b.sum();
    for (int i = 0; i < 3; ++i) size += mag(t[i]);
    const Real slack = Real(1e-9) * size;
    auto separated = [slack](Interval dist, Interval radius) {
        return abs(dist).lo > radius.hi + slack;
    };
    for (int i = 0; i < 3; ++i) {
        const Interval r = point(a[i]) + abs_rot[i][0] * point(b[0]) +
                           abs_rot[i][1] * point(b[1]) + abs_rot[i][2] * point(b[2]);
        if (separated(t[i], r)) return false;
    }
    for (int j = 0; j < 3; ++j) {
        const Interval dist = t[0] * rot[0][j] + t[1] * rot[1][j] + t[2] * rot[2][j];
        const Interval r = abs_rot[0][j] * point(a[0]) + abs_rot[1][j] * point(a[1]) +
                           abs_rot[2][j] * point(a[2]) + point(b[j]);
        if (separated(dist, r)) return false;
    }
    for (int i = 0; i < 3; ++i) {
        const int i1 = (i + 1) % 3;
        const int i2 = (i + 2) % 3;
        for (int j = 0; j < 3; ++j) {
            const int j1 = (j + 1) % 3;
            const int j2 = (j + 2) % 3;
            const Interval r = point(a[i1]) * abs_rot[i2][j] + point(a[i2]) * abs_rot[i1][j] +
                               point(b[j1]) * abs_rot[i][j2] + point(b[j2]) * abs_rot[i][j1];
            const Interval dist = t[i2] * rot[i1][j] - t[i1] * rot[i2][j];
            if (separated(dist, r)) return false;
        }
    }
    return true;
}

}  // namespace collision
