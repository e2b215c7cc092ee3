// collision/math.h -- the only file that spells Eigen types: Real, Vec3, Mat3, Quat, Pose.
// Everything in cdlab computes in Real (double unless built with CDLAB_USE_FLOAT).
#pragma once

#include <numbers>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace collision {

#ifdef CDLAB_USE_FLOAT
using Real = float;
#else
using Real = double;
#endif

using Vec3 = Eigen::Matrix<Real, 3, 1>;
using Mat3 = Eigen::Matrix<Real, 3, 3>;
using Quat = Eigen::Quaternion<Real>;

/// Relative epsilon of Real: tolerances are this times a length scale of the objects involved.
inline constexpr Real kEpsilon = Eigen::NumTraits<Real>::epsilon();

/// pi, rounded to Real.
inline constexpr Real kPi = std::numbers::pi_v<Real>;

/// A rigid transform: world = orientation * local + position. `orientation` is a unit quaternion.
struct Pose {
    Vec3 position = Vec3::Zero();
    Quat orientation = Quat::Identity();

    /// Local point to world.
    Vec3 apply(const Vec3& local) const { return orientation * local + position; }
    /// World point to local.
    Vec3 applyInverse(const Vec3& world) const {
        return orientation.conjugate() * (world - position);
    }
    Mat3 rotation() const { return orientation.toRotationMatrix(); }
    /// this * other: first other, then this.
    Pose operator*(const Pose& other) const {
        return Pose{apply(other.position), orientation * other.orientation};
    }
    Pose inverse() const {
        const Quat inv = orientation.conjugate();
        return Pose{-(inv * position), inv};
    }
};

}  // namespace collision
