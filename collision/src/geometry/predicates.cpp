// collision/src/geometry/predicates.cpp -- exact-sign orient2d/orient3d.
// Invariant: every returned sign equals the sign of the exact real determinant of the given
// doubles. A double evaluation is trusted only when |det| exceeds Shewchuk's a-priori error bound
// (Shewchuk 1997, "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
// Predicates", §4.3, errboundA); otherwise the determinant is recomputed exactly as a
// nonoverlapping expansion (ibid. §2: Two-Sum, Two-Product, Grow-Expansion, Scale-Expansion) and
// the sign of its largest component is returned.
#include "geometry/predicates.h"

#include <array>
#include <cmath>

#include "collision/assert.h"

namespace collision {

namespace {

// Shewchuk's epsilon: half an ulp of 1, 2^-53.
constexpr double kHalfUlp = 1.1102230246251565e-16;
constexpr double kOrient2dBound = (3.0 + 16.0 * kHalfUlp) * kHalfUlp;  // Shewchuk ccwerrboundA
constexpr double kOrient3dBound = (7.0 + 56.0 * kHalfUlp) * kHalfUlp;  // Shewchuk o3derrboundA

// A nonoverlapping expansion, components in increasing magnitude, zeros eliminated (the exact
// value is the sum of the components; its sign is the sign of the last one).
struct Expansion {
    static constexpr int kCapacity = 256;
    std::array<double, kCapacity> c{};
    int n = 0;

    void push(double x) {
        CDLAB_ASSERT(n < kCapacity, "expansion overflow");
        c[static_cast<std::size_t>(n++)] = x;
    }
    int sign() const {
        if (n == 0) return 0;
        const double top = c[static_cast<std::size_t>(n - 1)];
        return top > 0 ? 1 : (top < 0 ? -1 : 0);
    }
};

// Shewchuk §2.5 Two-Sum: x + y == a + b exactly, x = fl(a + b).
inline void twoSum(double a, double b, double& x, double& y) {
    x = a + b;
    const double b_virtual = x - a;
    const double a_virtual = x - b_virtual;
    y = (a - a_virtual) + (b - b_virtual);
}

// x + y == a * b exactly (fused multiply-add gives the rounding error of the product).
inline void twoProduct(double a, double b, double& x, double& y) {
    x = a * b;
    y = std::fma(a, b, -x);
}

// b - a as a two-component expansion.
Expansion difference(double b, double a) {
    double x = 0;
    double y = 0;
    twoSum(b, -a, x, y);
    Expansion e;
    if (y != 0) e.push(y);
    if (x != 0 || e.n == 0) e.push(x);
    return e;
}

// Shewchuk Grow-Expansion with zero elimination: e + b.
Expansion grow(const Expansion& e, double b) {
    Expansion h;
    double q = b;
    for (int i = 0; i < e.n; ++i) {
        double sum = 0;
        double err = 0;
        twoSum(q, e.c[static_cast<std::size_t>(i)], sum, err);
        q = sum;
        if (err != 0) h.push(err);
    }
    if (q != 0 || h.n == 0) h.push(q);
    return h;
}

// e + f by repeated growth (Shewchuk Theorem 10 applied component by component).
Expansion add(const Expansion& e, const Expansion& f) {
    Expansion h = e;
    for (int i = 0; i < f.n; ++i) h = grow(h, f.c[static_cast<std::size_t>(i)]);
    return h;
}

Expansion negate(Expansion e) {
    for (int i = 0; i < e.n; ++i)
        e.c[static_cast<std::size_t>(i)] = -e.c[static_cast<std::size_t>(i)];
    return e;
}

// Shewchuk Scale-Expansion with zero elimination: e * b.
Expansion scale(const Expansion& e, double b) {
    Expansion h;
    if (e.n == 0) {
        h.push(0);
        return h;
    }
    double q = 0;
    double hh = 0;
    twoProduct(e.c[0], b, q, hh);
    if (hh != 0) h.push(hh);
    for (int i = 1; i < e.n; ++i) {
        double p1 = 0;
        double p0 = 0;
        twoProduct(e.c[static_cast<std::size_t>(i)], b, p1, p0);
        double sum = 0;
        twoSum(q, p0, sum, hh);
        if (hh != 0) h.push(hh);
        // Fast-Two-Sum is valid here (|p1| >= |sum|, Shewchuk Theorem 19); Two-Sum is also exact.
        twoSum(p1, sum, q, hh);
        if (hh != 0) h.push(hh);
    }
    if (q != 0 || h.n == 0) h.push(q);
    return h;
}

Expansion multiply(const Expansion& e, const Expansion& f) {
    Expansion h;
    h.push(0);
    for (int i = 0; i < f.n; ++i) h = add(h, scale(e, f.c[static_cast<std::size_t>(i)]));
    return h;
}

// u0 * v1 - u1 * v0, exactly.
Expansion cross2(const Expansion& u0, const Expansion& u1, const Expansion& v0,
                 const Expansion& v1) {
    return add(multiply(u0, v1), negate(multiply(u1, v0)));
}

int orient3dExact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    const Expansion ux = difference(double(b.x()), double(a.x()));
    const Expansion uy = difference(double(b.y()), double(a.y()));
    const Expansion uz = difference(double(b.z()), double(a.z()));
    const Expansion vx = difference(double(c.x()), double(a.x()));
    const Expansion vy = difference(double(c.y()), double(a.y()));
    const Expansion vz = difference(double(c.z()), double(a.z()));
    const Expansion wx = difference(double(d.x()), double(a.x()));
    const Expansion wy = difference(double(d.y()), double(a.y()));
    const Expansion wz = difference(double(d.z()), double(a.z()));
    // det[u, v, w] = u . (v x w), cofactor expansion along u.
    const Expansion t0 = multiply(ux, cross2(vy, vz, wy, wz));
    const Expansion t1 = multiply(uy, cross2(vz, vx, wz, wx));
    const Expansion t2 = multiply(uz, cross2(vx, vy, wx, wy));
    return add(add(t0, t1), t2).sign();
}

}  // namespace

int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    const double ux = double(b.x()) - double(a.x());
    const double uy = double(b.y()) - double(a.y());
    const double uz = double(b.z()) - double(a.z());
    const double vx = double(c.x()) - double(a.x());
    const double vy = double(c.y()) - double(a.y());
    const double vz = double(c.z()) - double(a.z());
    const double wx = double(d.x()) - double(a.x());
    const double wy = double(d.y()) - double(a.y());
    const double wz = double(d.z()) - double(a.z());
    const double m0a = vy * wz;
    const double m0b = vz * wy;
    const double m1a = vz * wx;
    const double m1b = vx * wz;
    const double m2a = vx * wy;
    const double m2b = vy * wx;
    const double det = ux * (m0a - m0b) + uy * (m1a - m1b) + uz * (m2a - m2b);
    const double permanent = std::fabs(ux) * (std::fabs(m0a) + std::fabs(m0b)) +
                             std::fabs(uy) * (std::fabs(m1a) + std::fabs(m1b)) +
                             std::fabs(uz) * (std::fabs(m2a) + std::fabs(m2b));
    const double bound = kOrient3dBound * permanent;
    if (det > bound) return 1;
    if (-det > bound) return -1;
    if (permanent == 0) return 0;  // every product is zero exactly: so is the determinant
    return orient3dExact(a, b, c, d);
}

int orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
    const double left = (ax - cx) * (by - cy);
    const double right = (ay - cy) * (bx - cx);
    const double det = left - right;
    const double bound = kOrient2dBound * (std::fabs(left) + std::fabs(right));
    if (det > bound) return 1;
    if (-det > bound) return -1;
    if (left == 0 && right == 0) {
        // Products of rounded differences are zero only when a difference is exactly zero (or
        // underflows), so the exact determinant is zero too.
        return 0;
    }
    const Expansion e =
        cross2(difference(ax, cx), difference(ay, cy), difference(bx, cx), difference(by, cy));
    return e.sign();
}

}  // namespace collision
