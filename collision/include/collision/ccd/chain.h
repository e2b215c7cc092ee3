// collision/ccd/chain.h -- articulated chains: links joined by revolute, prismatic or fixed
// joints driven by prescribed joint trajectories; forward kinematics, per-link motion bounds
// composed along the chain, and the articulated time of impact that the engine's continuous
// stage runs on chain links (chain.cpp: model, kinematics, bounds; articulated.cpp: the query).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "collision/ccd/ccd.h"
#include "collision/math.h"
#include "collision/volumes/bounding_volumes.h"

namespace collision {

struct Shape;

/// A joint's prescribed value over time: rad (revolute) or m (prismatic); t in seconds.
/// Well-formedness (finite numbers, strictly increasing key times) is the scene loader's to
/// check; the functions below assert on it and never loop on bad input.
struct JointTrajectory {
    enum class Kind : std::uint8_t { Constant, Ramp, Sine, Keyframes };
    Kind kind = Kind::Constant;
    Real value = 0;      ///< Constant: q. Ramp: q(0). Sine: the offset. Keyframes without keys: q.
    Real rate = 0;       ///< Ramp: q = value + rate t (per second)
    Real amplitude = 0;  ///< Sine: q = value + amplitude sin(2 pi frequency t + phase)
    Real frequency = 0;  ///< Sine, Hz
    Real phase = 0;      ///< Sine, rad
    /// Keyframes: (time s, value), times strictly increasing; linear between keys, held
    /// constant before the first and after the last.
    std::vector<std::pair<Real, Real>> keys;
    /// q(t). Keyframes: O(log keys).
    Real at(Real t) const;
    /// Upper bound of |dq/dt| over [t0, t1] (conservative: never below the true maximum, also
    /// not below the slope of at() between any two times of the interval). t0 > t1 is read as
    /// [t1, t0]. Keyframes: the steepest segment touching the closed interval.
    Real maxRate(Real t0, Real t1) const;
    /// Lower and upper bound of q over [t0, t1] (conservative: contains at(t) for every t of the
    /// interval, rounding included). t0 > t1 is read as [t1, t0].
    std::pair<Real, Real> range(Real t0, Real t1) const;
};

enum class JointType : std::uint8_t { Revolute, Prismatic, Fixed };

/// Link i hangs from link `parent` (parent < i; -1: the chain's base) by joint i:
/// frame_i(t) = frame_parent(t) * origin * J(q_i(t)); J turns by q about `axis` (revolute),
/// slides by q along it (prismatic), or is the identity (fixed).
struct ChainJoint {
    JointType type = JointType::Revolute;
    int parent = -1;
    Pose origin;                ///< joint frame in the parent's frame (or the base frame)
    Vec3 axis = Vec3::UnitZ();  ///< unit, joint frame (normalised again by the kinematics)
    JointTrajectory trajectory;
};

struct Chain {
    Pose base;                       ///< world pose of the base frame (fixed over time)
    std::vector<ChainJoint> joints;  ///< joint i carries link i; parents before children
    /// Every point of link i lies within this distance of its frame's origin (m); the
    /// caller sets it from the link's shape and its placement in the link frame.
    std::vector<Real> link_radius;
};

/// World frame of every link at time t (s); `out` is resized to the link count. O(links).
void chainFrames(const Chain& chain, Real t, std::vector<Pose>& out);

/// World frame of one link at time t (s), composed along its path only (no allocation): the
/// same value as chainFrames(chain, t, out)[link]. O(path length).
Pose linkFrame(const Chain& chain, int link, Real t);

/// The same frame with its position taken about `origin` (world axes): world position - origin,
/// composed from base.position - origin so that a chain far from the world origin loses
/// nothing to its distance (origin = base.position: no rounding of the base's offset at all).
Pose linkFrame(const Chain& chain, int link, Real t, const Vec3& origin);

/// Upper bound (m/s) of the speed of any point of link `link` over [t0, t1], composed link
/// to link along the path from the base (Zhang et al. 2007): revolute joint j contributes
/// maxRate_j times the largest distance from its axis to a point of the link, bounded by the
/// joint-to-joint offsets along the path (prismatic extensions at their largest over the
/// interval) plus link_radius[link]; prismatic joint j contributes maxRate_j.
/// O(path length). The derivation is at the top of chain.cpp.
Real linkSpeedBound(const Chain& chain, int link, Real t0, Real t1);

/// The same bound for the points within `reach` (m) of link `link`'s frame origin instead of
/// link_radius[link] (a shape placed in the link frame: |its offset| + its bounding radius).
Real linkPointSpeedBound(const Chain& chain, int link, Real reach, Real t0, Real t1);

/// World AABB that contains link `link` (its geometry within link_radius of its frame
/// origin) at every time of [t0, t1]: conservative. The frame origin at the interval's middle,
/// grown by half the interval times linkSpeedBound plus the link radius (plus a rounding pad
/// relative to the chain's extent and distance from the world origin).
Aabb linkSweptBounds(const Chain& chain, int link, Real t0, Real t1);

/// One side of an articulated time-of-impact query: a chain link (chain != nullptr), with
/// its shape placed at `shape_in_link` in the link frame, or else a rigid shape moved by
/// `sweep` (collision::Sweep over the step; a static body has a zero sweep).
struct ArticulatedSide {
    const Shape* shape = nullptr;
    const Chain* chain = nullptr;
    int link = -1;
    Pose shape_in_link;
    Sweep sweep;
};

/// The step is [t0, t1] seconds; a step fraction s is the time t0 + s (t1 - t0). Result
/// times (ToiOutput::t) are step fractions, as for timeOfImpact. ToiQuery's sweep_a/b are
/// ignored (the sides carry the motion); t_max, target_gap, tolerance,
/// relative_tolerance, max_iterations mean what they mean for timeOfImpact.
struct ArticulatedToiInput : ToiQuery {
    ArticulatedSide side_a;
    ArticulatedSide side_b;
    Real t0 = 0;
    Real t1 = 0;
};

/// Conservative advancement (Mirtich 1996) with the articulated motion bound: the loop of
/// timeOfImpact (GJK gives a direction n and the gap along it at the sides' exact poses at s;
/// s advances by (gap - target_gap) / (mu_a + mu_b)), where a link side's mu is its fastest
/// point's speed over the rest of the step, linkPointSpeedBound on [t(s), t(t_max)] for the
/// shape's reach from the link origin, times t1 - t0, and a rigid side's mu is timeOfImpact's
/// directional bound. Either side may be a link, of one chain or of two.
/// Tolerance: as timeOfImpact, a Hit is accepted once the gap is within target_gap +
/// tolerance (0: relative_tolerance times the smaller bounding radius).
/// Guarantee: conservative -- t is never later than the first time the gap closes to
/// target_gap, however fast the joints turn within the step (a tip passing through a plate
/// between two clear step ends is a Hit), up to the rounding of the gap at the poses: both
/// sides are placed about the first chain's base (linkFrame about an origin), so this is a few
/// ulps of the query's own extent, whatever its distance from the world origin. Witness points
/// are returned in world coordinates. Separated: the gap
/// stays above target_gap on [0, t_max]. Overlapped: penetrating at s = 0.
/// Failure mode: Failed with a safe t (no contact on [0, t]) at the iteration cap -- fast
/// joints near grazing contact need many small advances -- and, at t = 0, on bad input (null
/// shape, link out of range, non-finite numbers, t1 < t0); non-finite poses from a malformed
/// trajectory end it Failed at the last safe t. A Mesh stands for its convex hull.
ToiOutput timeOfImpactArticulated(const ArticulatedToiInput& input);

/// Reference: the sides' poses (about the same origin as timeOfImpactArticulated) at
/// `samples` + 1 evenly spaced step fractions; Hit at the first sample where collide() reports
/// contact (Overlapped if at s = 0), else Separated.
/// Approximate: a contact shorter than a sample interval can be missed. Samples span
/// [0, t_max]; target_gap and the tolerances are ignored (contact means collide() says so).
/// iterations = samples tested. Cost: samples + 1 collide() calls at most.
ToiOutput firstContactSampled(const ArticulatedToiInput& input, int samples);

}  // namespace collision
