// tests/collision/test_random.h -- fixed-seed random helpers shared by the collision tests.
#pragma once

#include <cstdint>
#include <random>

#include "collision/math.h"

namespace cdlab_test {

using collision::Quat;
using collision::Real;
using collision::Vec3;

class Rng {
public:
    explicit Rng(std::uint64_t seed) : engine_(seed) {}
    Real uniform(Real lo, Real hi) { return std::uniform_real_distribution<Real>(lo, hi)(engine_); }
    int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(engine_); }
    /// Drawn in a fixed order, z then y then x: three draws as constructor arguments would be
    /// evaluated in an unspecified order (GCC right to left, clang left to right), so the same
    /// seed gave different samples under the two compilers. z-first keeps the samples the suite
    /// was written against (GCC's).
    Vec3 vec(Real lo, Real hi) {
        const Real z = uniform(lo, hi);
        const Real y = uniform(lo, hi);
        const Real x = uniform(lo, hi);
        return Vec3(x, y, z);
    }
    /// A uniformly random rotation (Shoemake's method).
    Quat rotation() {
        const Real u1 = uniform(0, 1);
        const Real u2 = uniform(0, 2 * Real(M_PI));
        const Real u3 = uniform(0, 2 * Real(M_PI));
        const Real a = std::sqrt(1 - u1);
        const Real b = std::sqrt(u1);
        return Quat(a * std::sin(u2), a * std::cos(u2), b * std::sin(u3), b * std::cos(u3))
            .normalized();
    }

private:
    std::mt19937_64 engine_;
};

}  // namespace cdlab_test
