// collision/src/ccd/naive.cpp -- the naive floating-point CCD baseline: roots of the coplanarity
// cubic in double, then inside tests with zero tolerance at each root (Provot 1997 §3; the
// "floating-point root finder" baselines of Wang et al. 2021 §6). No error bounds, on purpose:
// it exists to be measured against the conservative method in ccd/inclusion.cpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "collision/ccd/ccd.h"

namespace collision {
namespace {

/// Real roots of k3 t^3 + k2 t^2 + k1 t + k0 that lie in [0, 1], ascending. Standard
/// closed forms: Cardano / trigonometric for the cubic (Numerical Recipes 3rd ed. §5.6),
/// the cancellation-free quadratic, linear. An identically zero polynomial has no roots here
/// (the naive solver's blind spot: motion coplanar for the whole step).
int cubicRootsInUnit(double k3, double k2, double k1, double k0, std::array<double, 3>& roots) {
    std::array<double, 3> r{};
    int n = 0;
    if (k3 != 0) {
        // t^3 + a t^2 + b t + c = 0.
        const double a = k2 / k3;
        const double b = k1 / k3;
        const double c = k0 / k3;
        const double qq = (a * a - 3 * b) / 9;
        const double rr = (2 * a * a * a - 9 * a * b + 27 * c) / 54;
        const double qq3 = qq * qq * qq;
        if (rr * rr < qq3) {
            const double theta = std::acos(std::clamp(rr / std::sqrt(qq3), -1.0, 1.0));
            const double s = -2 * std::sqrt(qq);
            r[0] = s * std::cos(theta / 3) - a / 3;
            r[1] = s * std::cos((theta + 2 * std::numbers::pi) / 3) - a / 3;
            r[2] = s * std::cos((theta - 2 * std::numbers::pi) / 3) - a / 3;
            n = 3;
        } else {
            const double big_a =
                -std::copysign(std::cbrt(std::abs(rr) + std::sqrt(rr * rr - qq3)), rr);
            const double big_b = big_a != 0 ? qq / big_a : 0;
            r[0] = (big_a + big_b) - a / 3;
            n = 1;
        }
    } else if (k2 != 0) {
        const double disc = k1 * k1 - 4 * k2 * k0;
        if (disc >= 0) {
            const double q = -0.5 * (k1 + std::copysign(std::sqrt(disc), k1));
            r[n++] = q / k2;
            if (q != 0) r[n++] = k0 / q;
        }
    } else if (k1 != 0) {
        r[n++] = -k0 / k1;
    }
    int m = 0;
    for (int i = 0; i < n; ++i) {
        if (r[i] >= 0 && r[i] <= 1) roots[m++] = r[i];
    }
    std::sort(roots.begin(), roots.begin() + m);
    return m;
}

Vec3 lerp(const Vec3& a, const Vec3& b, Real t) { return a + t * (b - a); }

/// Coefficients of ((a(t) x b(t)) . c(t)) with a, b, c moving linearly: x(t) = x0 + t dx.
std::array<double, 4> tripleProductCubic(const Vec3& a0, const Vec3& da, const Vec3& b0,
                                         const Vec3& db, const Vec3& c0, const Vec3& dc) {
    const Vec3 ab0 = a0.cross(b0);
    const Vec3 ab1 = da.cross(b0) + a0.cross(db);
    const Vec3 ab2 = da.cross(db);
    return {ab0.dot(c0), ab1.dot(c0) + ab0.dot(dc), ab2.dot(c0) + ab1.dot(dc), ab2.dot(dc)};
}

/// Times in [0, 1] (ascending) at which the four linearly moving points x[0..3] (from t0 at
/// t = 0 to t1 at t = 1) are coplanar: roots of ((x_a - x_o) x (x_b - x_o)) . (x_c - x_o), with
/// (o, a, b, c) a permutation of 0..3. Returns how many were found.
int coplanarTimes(const std::array<Vec3, 4>& t0, const std::array<Vec3, 4>& t1, int o, int a,
                  int b, int c, std::array<double, 3>& roots) {
    const Vec3 a0 = t0[a] - t0[o];
    const Vec3 b0 = t0[b] - t0[o];
    const Vec3 c0 = t0[c] - t0[o];
    const Vec3 da = (t1[a] - t1[o]) - a0;
    const Vec3 db = (t1[b] - t1[o]) - b0;
    const Vec3 dc = (t1[c] - t1[o]) - c0;
    const std::array<double, 4> k = tripleProductCubic(a0, da, b0, db, c0, dc);
    return cubicRootsInUnit(k[3], k[2], k[1], k[0], roots);
}

}  // namespace

CcdOutput vertexFaceCcdNaive(const VertexFaceCcdInput& in) {
    CcdOutput out;
    out.state = CcdState::Separated;
    out.t = out.t_upper = 1;
    // (f1 - f0) x (f2 - f0) . (p - f0) = 0 when p is in the face's plane.
    std::array<double, 3> roots{};
    const int n = coplanarTimes(in.t0, in.t1, 1, 2, 3, 0, roots);
    for (int i = 0; i < n; ++i) {
        ++out.iterations;
        const Real t = static_cast<Real>(roots[i]);
        const Vec3 p = lerp(in.t0[0], in.t1[0], t);
        const Vec3 f0 = lerp(in.t0[1], in.t1[1], t);
        const Vec3 f1 = lerp(in.t0[2], in.t1[2], t);
        const Vec3 f2 = lerp(in.t0[3], in.t1[3], t);
        // Barycentric coordinates, RTCD 3.4 (Ericson), no tolerance.
        const Vec3 e1 = f1 - f0;
        const Vec3 e2 = f2 - f0;
        const Vec3 ep = p - f0;
        const double d11 = e1.dot(e1), d12 = e1.dot(e2), d22 = e2.dot(e2);
        const double dp1 = ep.dot(e1), dp2 = ep.dot(e2);
        const double denom = d11 * d22 - d12 * d12;
        if (denom == 0) continue;
        const double u = (d22 * dp1 - d12 * dp2) / denom;
        const double v = (d11 * dp2 - d12 * dp1) / denom;
        if (u >= 0 && v >= 0 && u + v <= 1) {
            out.state = CcdState::Hit;
            out.t = out.t_upper = t;
            out.u = u;
            out.v = v;
            return out;
        }
    }
    return out;
}

CcdOutput edgeEdgeCcdNaive(const EdgeEdgeCcdInput& in) {
    CcdOutput out;
    out.state = CcdState::Separated;
    out.t = out.t_upper = 1;
    // (a1 - a0) x (b0 - a0) . (b1 - a0) = 0 when the four endpoints are coplanar.
    std::array<double, 3> roots{};
    const int n = coplanarTimes(in.t0, in.t1, 0, 1, 2, 3, roots);
    for (int i = 0; i < n; ++i) {
        ++out.iterations;
        const Real t = static_cast<Real>(roots[i]);
        const Vec3 pa = lerp(in.t0[0], in.t1[0], t);
        const Vec3 qa = lerp(in.t0[1], in.t1[1], t);
        const Vec3 pb = lerp(in.t0[2], in.t1[2], t);
        const Vec3 qb = lerp(in.t0[3], in.t1[3], t);
        // Intersection parameters of the two (coplanar) lines, RTCD 5.1.9; parallel -> miss.
        const Vec3 d1 = qa - pa;
        const Vec3 d2 = qb - pb;
        const Vec3 r = pa - pb;
        const double a = d1.dot(d1), e = d2.dot(d2), f = d2.dot(r);
        const double c = d1.dot(r), b = d1.dot(d2);
        const double denom = a * e - b * b;
        if (denom == 0) continue;
        const double s = (b * f - c * e) / denom;
        const double w = (a * f - b * c) / denom;
        if (s >= 0 && s <= 1 && w >= 0 && w <= 1) {
            out.state = CcdState::Hit;
            out.t = out.t_upper = t;
            out.u = s;
            out.v = w;
            return out;
        }
    }
    return out;
}

}  // namespace collision
