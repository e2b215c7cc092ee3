// engine/src/box_pair_finder.h -- the candidate pairs of a stage that works on boxes of its own
// (the contact solver's AABBs grown by its margin, the continuous stage's swept bounds), found
// by an instance of the scene's broad phase rather than by a sweep private to the engine.
#pragma once

#include <algorithm>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "engine/body.h"
#include "engine/clone_ptr.h"

namespace engine {

/// One stage's pair finder: an instance of a registry broad phase (its own coherence state,
/// apart from the one that flags the drawn pairs) fed with the stage's boxes each step.
///
/// Exact: find() gives precisely the pairs whose boxes overlap (touching counts) and that
/// `keep` accepts, sorted by (a, b), whatever broad phase runs. A broad phase that decides on
/// spheres or OBBs gets the box's circumscribed sphere and the box as an OBB, both rounded
/// outward (kSlack) so they contain the box despite rounding; its pairs are then a superset,
/// and every one is tested on the boxes themselves. So the motion does not depend on the
/// choice of broad phase, only the cost does.
class BoxPairFinder {
public:
    /// Absolute slack, per unit of |min| + |max| on each axis, by which the sphere and OBB of a
    /// box are grown: a few ulps, more than the rounding of the centre and half extents.
    static constexpr Real kSlack = 8 * std::numeric_limits<Real>::epsilon();

    /// An instance of registry broad phase `name` (created at the first find()); throws
    /// std::invalid_argument then if the name is unknown.
    explicit BoxPairFinder(std::string name) : name_(std::move(name)) {}
    /// A copy with the same proxies and coherence state (BroadPhase::clone).
    std::unique_ptr<BoxPairFinder> clone() const { return std::make_unique<BoxPairFinder>(*this); }

    /// Drops the instance and its proxies: the next find() builds `name` from the boxes it
    /// gets (switching broad phase between steps).
    void reset(std::string name) {
        name_ = std::move(name);
        phase_.reset();
        inserted_ = 0;
    }

    /// Writes into `pairs` (cleared first) every (a, b), a < b, whose boxes overlap and for
    /// which keep(a, b) holds, sorted. boxes[i] is body i's box; bodies added since the last
    /// call are inserted.
    template <class Keep>
    void find(std::span<const collision::Aabb> boxes, Keep keep,
              std::vector<collision::ProxyPair>& pairs) {
        feed(boxes);
        counters_ = {};
        phase_->findPairs(pairs, counters_);
        std::erase_if(pairs, [&](const collision::ProxyPair& p) {
            return !boxes[static_cast<std::size_t>(p.a)].overlaps(
                       boxes[static_cast<std::size_t>(p.b)]) ||
                   !keep(static_cast<BodyId>(p.a), static_cast<BodyId>(p.b));
        });
    }

    /// The broad phase's counters of the last find().
    const collision::BroadPhaseCounters& counters() const { return counters_; }
    const std::string& name() const { return name_; }

    /// The volumes a sphere or OBB broad phase is given for `box`: they contain it.
    static collision::ProxyVolumes conservativeVolumes(const collision::Aabb& box);

private:
    void feed(std::span<const collision::Aabb> boxes);

    std::string name_;
    ClonePtr<collision::BroadPhase> phase_;
    bool decides_on_boxes_ = true;  ///< the registry row decides on AABBs
    std::size_t inserted_ = 0;      ///< proxies 0 .. inserted_ - 1 are present
    std::vector<collision::ProxyVolumes> scratch_;
    collision::BroadPhaseCounters counters_;
};

}  // namespace engine
