// engine/src/deformation.cpp -- the prescribed deformations (global deformations after Barr,
// "Global and local deformations of solid primitives", SIGGRAPH 1984: bend and twist about an
// axis), as closed forms of (rest position, time).
#include "engine/deformation.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace engine {

using collision::kPi;
using collision::Real;
using collision::Vec3;

namespace {

// sin^2(pi f t): 0 at t = 0, 1 at t = 1 / (2 f).
Real swell(Real frequency, Real t) {
    const Real s = std::sin(std::numbers::pi_v<Real> * frequency * t);
    return s * s;
}

}  // namespace

Vec3 deformPoint(const Deformation& d, const Vec3& rest, Real t) {
    const Real x = rest.x();
    const Real y = rest.y();
    const Real z = rest.z();
    switch (d.kind) {
        case DeformKind::Bend: {
            // The line y = 0 becomes a circle of radius r = 1 / k through the origin, centred at
            // (0, r): arc length x maps to angle phi = k x, and a point at height y stays at
            // distance r - y from the centre (Barr 1984 §4). Written without r so k -> 0 has no
            // cancellation: (r - y) sin(phi) = sin(phi) / k - y sin(phi) and
            // r - (r - y) cos(phi) = 2 sin^2(phi / 2) / k + y cos(phi).
            const Real k = d.amount * swell(d.frequency, t);
            if (k == 0) return rest;
            const Real phi = k * x;
            const Real half = std::sin(phi / 2);
            return Vec3(std::sin(phi) / k - y * std::sin(phi),
                        2 * half * half / k + y * std::cos(phi), z);
        }
        case DeformKind::Twist: {
            const Real angle = d.amount * swell(d.frequency, t) * x;
            const Real c = std::cos(angle);
            const Real s = std::sin(angle);
            return Vec3(x, c * y - s * z, s * y + c * z);
        }
        case DeformKind::Wave: {
            const Real phase = 2 * std::numbers::pi_v<Real> * (x / d.wavelength - d.frequency * t);
            return Vec3(x, y + d.amount * std::sin(phase), z);
        }
    }
    return rest;
}

Real deformSpeedBound(const Deformation& d, std::span<const Vec3> rest) {
    // Bend and twist vary with the strength k = amount s(t), s = sin^2(pi f t), whose rate
    // |ds/dt| = pi f |sin(2 pi f t)| is at most pi f.
    const Real strength_rate = kPi * d.frequency * std::abs(d.amount);
    Real bound = 0;
    for (const Vec3& v : rest) {
        const Real x = std::abs(v.x());
        switch (d.kind) {
            case DeformKind::Bend:
                // p(k) = c(k) + y n(k), c(k) = integral over [0, x] of (cos ku, sin ku) du and
                // n(k) = (-sin kx, cos kx): |dc/dk| <= x^2 / 2 and |dn/dk| = |x|.
                bound = std::max(bound, strength_rate * (x * x / 2 + x * std::abs(v.y())));
                break;
            case DeformKind::Twist:
                // A point at distance rho from the x axis turns by k x: speed rho |x| dk/dt.
                bound = std::max(bound, strength_rate * x * std::hypot(v.y(), v.z()));
                break;
            case DeformKind::Wave:
                // d/dt amount sin(2 pi (x / wavelength - f t)) = -2 pi f amount cos(...).
                bound = 2 * kPi * d.frequency * std::abs(d.amount);
                break;
        }
    }
    return bound;
}

std::string_view deformKindName(DeformKind kind) {
    switch (kind) {
        case DeformKind::Bend:
            return "bend";
        case DeformKind::Twist:
            return "twist";
        case DeformKind::Wave:
            return "wave";
    }
    return "?";
}

}  // namespace engine
