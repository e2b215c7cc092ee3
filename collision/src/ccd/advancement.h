// collision/src/ccd/advancement.h -- the one conservative-advancement loop (Mirtich 1996),
// shared by the rigid time of impact (advancement.cpp) and the articulated one
// (articulated.cpp): each supplies the poses at a step fraction and the bound on how fast the
// gap along a direction can shrink. Private to collision.
#pragma once

#include "collision/ccd/ccd.h"
#include "collision/geometry/shape.h"
#include "collision/math.h"

namespace collision {

/// How the two shapes of an advancement move over the step (fractions s in [0, 1]).
class AdvancementMotion {
public:
    virtual ~AdvancementMotion() = default;
    /// World poses of A and B at step fraction s.
    virtual Pose poseA(Real s) const = 0;
    virtual Pose poseB(Real s) const = 0;
    /// Upper bound, per unit step fraction, of the rate at which the gap between the shapes
    /// along the fixed unit world direction n (A towards B) can shrink, at any time of
    /// [s, t_max]. May be negative (the pair separates along n), +inf, or NaN (-> Failed).
    virtual Real approachRate(Real s, const Vec3& n) const = 0;
};

/// The advancement loop: at the current s, GJK between the shapes at their poses gives n and
/// the gap along it (a lower bound on the distance); s advances by (gap - target_gap) / rate.
/// Acceptance, tolerance, t_max, the iteration cap and the output are those of timeOfImpact
/// (ccd.h). Non-finite poses -> Failed at the last safe s. Validates the query's numbers.
ToiOutput advanceConservatively(const Shape& a, const Shape& b, const ToiQuery& query,
                                const AdvancementMotion& motion);

/// The rigid bound of timeOfImpact: the rate per unit step fraction at which the gap along
/// unit n (A towards B) can shrink when A moves by `sweep_a` and B by `sweep_b`:
/// (dA - dB).n + |rotA x n| ra + |rotB x n| rb + spin_speed, with ra, rb the shapes' bounding
/// radii about their local origins and spin_speed = spinSpeed(A) + spinSpeed(B). One side
/// alone: pass a zero sweep and radius 0 for the other (the zero terms add exactly).
Real sweepApproachRate(const Sweep& sweep_a, const Sweep& sweep_b, const Vec3& n, Real ra, Real rb,
                       Real spin_speed);

/// The rate per unit step fraction that a deforming shape's surface adds to the approach when it
/// moves up to `deform_speed` (m per step) relative to the body frame while the body moves by
/// `sweep`: deform_speed (1 + |rotation| + |spin|). The loop also takes deform_speed t off the
/// gap it measures on the t = 0 shapes (ToiQuery::deform_speed_a/_b). 0 for a rigid shape.
Real deformApproachRate(Real deform_speed, const Sweep& sweep);

/// |spin| times the largest distance of the shape's points from the spin axis through its
/// local origin: the fastest a point moves by the body-frame spin, per unit step fraction.
Real spinSpeed(const Shape& shape, const Vec3& spin);

/// Largest distance of the shape (rounding radius included) from its local origin.
Real shapeBoundingRadius(const Shape& shape);

/// All of the sweep's numbers are finite.
bool finiteSweep(const Sweep& s);

}  // namespace collision
