// collision/src/ccd/articulated.cpp -- time of impact of a chain link against a rigid shape or
// another link: conservative advancement (advancement.h) with the articulated motion bound of
// chain.cpp, and the sampled reference it is tested against.
// Invariant: a link side's bound is the speed of its fastest point over the rest of the step
// (Zhang, Redon, Lee, Kim 2007), a rigid side's the directional bound of timeOfImpact; their
// sum bounds how fast any gap along a fixed direction can shrink, so no advance passes the
// first time the gap closes to target_gap.
#include <algorithm>
#include <cmath>

#include "ccd/advancement.h"
#include "collision/ccd/chain.h"
#include "collision/geometry/shape.h"
#include "collision/narrowphase/narrow_phase.h"

namespace collision {

namespace {

Real stepTime(const ArticulatedToiInput& in, Real s) { return in.t0 + s * (in.t1 - in.t0); }

// Both sides are placed about one origin, the first chain's base (or A's start): a chain far
// from the world origin then loses nothing to that distance (linkFrame about an origin), and
// the gap is computed from positions of the size of the scene around the query.
Vec3 queryOrigin(const ArticulatedToiInput& in) {
    if (in.side_a.chain != nullptr) return in.side_a.chain->base.position;
    if (in.side_b.chain != nullptr) return in.side_b.chain->base.position;
    return in.side_a.sweep.start.position;
}

// The side's shape at step fraction s, position about `origin`.
Pose sidePose(const ArticulatedToiInput& in, const ArticulatedSide& side, Real s,
              const Vec3& origin) {
    if (side.chain == nullptr) {
        Sweep shifted = side.sweep;
        shifted.start.position -= origin;
        return shifted.at(s);
    }
    return linkFrame(*side.chain, side.link, stepTime(in, s), origin) * side.shape_in_link;
}

bool validSide(const ArticulatedSide& side) {
    if (side.shape == nullptr) return false;
    if (side.chain == nullptr) return finiteSweep(side.sweep);
    return side.link >= 0 && static_cast<std::size_t>(side.link) < side.chain->joints.size() &&
           side.shape_in_link.position.allFinite() &&
           side.shape_in_link.orientation.coeffs().allFinite();
}

bool validInput(const ArticulatedToiInput& in) {
    return validSide(in.side_a) && validSide(in.side_b) && std::isfinite(in.t0) &&
           std::isfinite(in.t1) && in.t1 >= in.t0;
}

// The motion of an articulated query: each side a link (its frame by forward kinematics) or a
// rigid sweep. A link's shape lies within reach = |shape_in_link.position| + its bounding
// radius of the link's frame origin, so linkPointSpeedBound(reach) bounds every point of it.
class ArticulatedMotion final : public AdvancementMotion {
public:
    explicit ArticulatedMotion(const ArticulatedToiInput& in)
        : in_(in),
          origin_(queryOrigin(in)),
          reach_a_(reach(in.side_a)),
          reach_b_(reach(in.side_b)),
          spin_speed_(spin(in.side_a) + spin(in.side_b)),
          t_end_(stepTime(in, std::clamp(in.t_max, Real(0), Real(1)))) {}

    Pose poseA(Real s) const override { return sidePose(in_, in_.side_a, s, origin_); }
    Pose poseB(Real s) const override { return sidePose(in_, in_.side_b, s, origin_); }
    const Vec3& origin() const { return origin_; }

    Real approachRate(Real s, const Vec3& n) const override {
        // Rigid sides: the bound of timeOfImpact, a link side standing in as a zero sweep of
        // radius 0 (its terms vanish exactly). Link sides: their fastest point's speed (m/s)
        // over [t(s), t(t_max)] times the step's length (s) per unit step fraction, whatever n.
        const Sweep still;
        const Sweep& sa = in_.side_a.chain == nullptr ? in_.side_a.sweep : still;
        const Sweep& sb = in_.side_b.chain == nullptr ? in_.side_b.sweep : still;
        Real rate = sweepApproachRate(sa, sb, n, in_.side_a.chain == nullptr ? reach_a_ : 0,
                                      in_.side_b.chain == nullptr ? reach_b_ : 0, spin_speed_);
        const Real t = stepTime(in_, s);
        const Real duration = in_.t1 - in_.t0;
        if (in_.side_a.chain != nullptr) {
            rate += linkPointSpeedBound(*in_.side_a.chain, in_.side_a.link, reach_a_, t, t_end_) *
                    duration;
        }
        if (in_.side_b.chain != nullptr) {
            rate += linkPointSpeedBound(*in_.side_b.chain, in_.side_b.link, reach_b_, t, t_end_) *
                    duration;
        }
        return rate;
    }

private:
    // Rigid side: the shape's bounding radius about its local origin (timeOfImpact's ra).
    // Link side: the shape's reach from the link's frame origin.
    static Real reach(const ArticulatedSide& side) {
        const Real r = shapeBoundingRadius(*side.shape);
        return side.chain == nullptr ? r : side.shape_in_link.position.norm() + r;
    }
    static Real spin(const ArticulatedSide& side) {
        return side.chain == nullptr ? spinSpeed(*side.shape, side.sweep.spin) : Real(0);
    }

    const ArticulatedToiInput& in_;
    Vec3 origin_;
    Real reach_a_;
    Real reach_b_;
    Real spin_speed_;
    Real t_end_;
};

}  // namespace

ToiOutput timeOfImpactArticulated(const ArticulatedToiInput& input) {
    if (!validInput(input)) return ToiOutput{};
    const ArticulatedMotion motion(input);
    ToiOutput out = advanceConservatively(*input.side_a.shape, *input.side_b.shape, input, motion);
    if (out.normal.squaredNorm() > 0) {  // witnesses were set with the normal: back to world
        out.point_a += motion.origin();
        out.point_b += motion.origin();
    }
    return out;
}

ToiOutput firstContactSampled(const ArticulatedToiInput& input, int samples) {
    ToiOutput out;
    if (!validInput(input)) return out;
    samples = std::max(samples, 1);
    const Real t_max = std::clamp(input.t_max, Real(0), Real(1));
    const Shape& a = *input.side_a.shape;
    const Shape& b = *input.side_b.shape;
    const Vec3 origin = queryOrigin(input);
    for (int k = 0; k <= samples; ++k) {
        const Real s = k == samples ? t_max : t_max * Real(k) / Real(samples);
        const Pose pa = sidePose(input, input.side_a, s, origin);
        const Pose pb = sidePose(input, input.side_b, s, origin);
        const CollideOutput c = collide(a, pa, b, pb);
        out.iterations = k + 1;
        if (c.state == ContactState::Failed) {
            out.state = CcdState::Failed;  // t: the last sample seen apart
            return out;
        }
        if (c.state != ContactState::Separated) {
            out.state = k == 0 && c.state == ContactState::Penetrating ? CcdState::Overlapped
                                                                       : CcdState::Hit;
            out.t = s;
            out.distance = 0;
            return out;
        }
        out.t = s;
        out.distance = c.distance;
    }
    out.state = CcdState::Separated;
    return out;
}

}  // namespace collision
