// engine/deformation.h -- prescribed shape change of a mesh body (bend, twist, wave): a vertex's
// position in the body frame is a pure function of its rest position and the time, so a run is
// deterministic. The world applies it every step and refits the body's hierarchy (world.h).
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "collision/math.h"

namespace engine {

enum class DeformKind : std::uint8_t {
    Bend,   ///< curls the body's local x axis into a circular arc in the x-y plane
    Twist,  ///< turns each cross-section about local x by an angle proportional to its x
    Wave,   ///< a travelling transverse wave: y moves by amount sin(2 pi (x / wavelength - f t))
};

/// Scene key `deform: {kind, amount, frequency, wavelength}` on a mesh body. The body's rest
/// shape is its mesh as loaded (centred on its centre of mass); its long axis is local x. Bend
/// and twist swell and relax as s(t) = sin^2(pi f t): rest shape at t = 0, full strength at
/// t = 1 / (2 f). The deformation is kinematic: mass and inertia stay those of the rest shape.
struct Deformation {
    DeformKind kind = DeformKind::Bend;
    /// Bend: curvature at full strength, 1/m (the arc has radius 1 / (s amount); a body of
    /// length L closes a ring at amount = 2 pi / L). Twist: rad per m of x at full strength.
    /// Wave: amplitude, m.
    collision::Real amount = 0;
    collision::Real frequency = 0;   ///< Hz, >= 0
    collision::Real wavelength = 1;  ///< m, > 0; wave only
};

/// Where the point at `rest` (body frame, m) is at time `t` (s).
collision::Vec3 deformPoint(const Deformation& d, const collision::Vec3& rest, collision::Real t);

/// A bound (m/s) on the speed of every point of the deformed mesh at every time: the largest
/// over the rest vertices `rest` of a closed-form bound on |d/dt deformPoint(d, v, t)|. Points of
/// its triangles and of its convex hull are convex combinations of vertices, so they move no
/// faster. Wave: 2 pi |amount| f. Twist: pi f |amount| |x| sqrt(y^2 + z^2). Bend:
/// pi f |amount| (x^2 / 2 + |x y|) (deformation.cpp).
collision::Real deformSpeedBound(const Deformation& d, std::span<const collision::Vec3> rest);

/// "bend", "twist", "wave".
std::string_view deformKindName(DeformKind kind);

}  // namespace engine
