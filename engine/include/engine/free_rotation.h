// engine/free_rotation.h -- the orientation update of a torque-free rigid body, by the symmetric
// splitting of the free rigid body into rotations about its principal axes (Reich 1994;
// Dullweber, Leimkuhler & McLachlan, J. Chem. Phys. 107, 1997; Fasso 2003). The integrators use it
// for the rotational part of a step: it keeps the world angular momentum exactly and, being
// symplectic and time-reversible, keeps the kinetic energy within a bounded O(dt^2) band for any
// number of steps, where explicit updates let it drift steadily.
#pragma once

#include "collision/math.h"

namespace engine {

using collision::Mat3;
using collision::Quat;
using collision::Real;
using collision::Vec3;

/// The principal axes of a body-frame inertia tensor: inertia = Q diag(moments) Q^T, with Q a
/// proper rotation (det +1) stored as the quaternion `axes` (principal -> body coordinates).
struct PrincipalFrame {
    Quat axes = Quat::Identity();
    Vec3 moments = Vec3::Ones();  ///< kg m^2, > 0, ascending
};

/// Eigen-decomposition of a symmetric positive inertia tensor (Eigen's iterative solver, accurate
/// to rounding even for repeated moments; deterministic). Equal moments give any orthonormal
/// axes, which is as good as any other.
PrincipalFrame principalFrame(const Mat3& inertia_body);

/// Orientation after `dt` seconds of torque-free motion from `orientation` (body -> world) with
/// world angular momentum `angular_momentum` (constant without torque). Splitting about the
/// middle principal moment (Fasso, "Comparison of splitting algorithms for the rigid body",
/// J. Comput. Phys. 189, 2003): an exact spin about L, then Strang-composed exact spins about
/// principal axes 1 and 3. Guarantee: exact for spherical and axisymmetric bodies; second order
/// otherwise; |L| exact (L is not touched); energy error bounded, no secular drift (backward
/// error analysis of symplectic maps). Cost: 4 axis rotations. Result unit length to rounding.
Quat advanceFreeRotation(const Quat& orientation, const Vec3& angular_momentum,
                         const PrincipalFrame& frame, Real dt);

}  // namespace engine
