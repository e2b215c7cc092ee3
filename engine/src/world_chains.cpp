// engine/src/world_chains.cpp -- the World's articulated chains: links are kinematic bodies posed
// every step by collision::chainFrames at the chain's clock; parent-child link pairs are dropped
// after the broad phase (unless collide_adjacent); in the continuous stage a link's swept bounds
// come from its joint motion (collision::linkSweptBounds, the motion bounds composed link to
// link of Zhang, Redon, Lee, Kim, "Continuous Collision Detection for Articulated Models using
// Taylor Models and Temporal Culling", SIGGRAPH 2007) and its pairs from
// collision::timeOfImpactArticulated; on_impact: stop halts the chain's clock at its earliest
// time of impact.
// Invariant: a running chain's clock equals time() after every step, a halted one's the time of
// impact it halted at, and every link's pose is chainFrames(clock)[link] * shape_in_link. Chains,
// links and events are visited in index order, so runs are bit-identical.
#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "collision/assert.h"
#include "collision/ccd/chain.h"
#include "collision/debug_draw.h"
#include "engine/world.h"
#include "toi_query.h"
#include "world_records.h"

namespace engine {

namespace {

// Iteration cap of one articulated time-of-impact query (as the rigid pairs' in
// world_continuous.cpp; Failed -> the pair is stopped at the safe time).
constexpr int kLinkMaxIterations = 64;

// Half-width of the central difference of a link's prescribed velocity, as a fraction of the
// step: the joint trajectories are smooth or piecewise linear, so the O(h^2) error is far below
// the step's own and the rounding ((1e-16 |x|) / h) stays negligible.
constexpr Real kVelocityStepFraction = Real(1e-4);

}  // namespace

void World::addChain(ChainSpec chain) {
    const std::size_t n = chain.chain.joints.size();
    if (n == 0 || chain.links.size() != n || chain.shape_in_link.size() != n ||
        chain.chain.link_radius.size() != n) {
        throw std::invalid_argument("chain '" + chain.name +
                                    "': joints, links, shape_in_link and link_radius must have "
                                    "the same non-zero size");
    }
    if (link_of_.size() < bodies_.size()) link_of_.resize(bodies_.size());
    const int c = static_cast<int>(chains_.size());
    for (std::size_t l = 0; l < n; ++l) {
        const BodyId id = chain.links[l];
        if (id < 0 || static_cast<std::size_t>(id) >= bodies_.size() ||
            link_of_[static_cast<std::size_t>(id)].chain >= 0) {
            throw std::invalid_argument("chain '" + chain.name + "': link " + std::to_string(l) +
                                        " is not a body, or a link of another chain");
        }
        const int parent = chain.chain.joints[l].parent;
        if (parent < -1 || parent >= static_cast<int>(l)) {
            throw std::invalid_argument("chain '" + chain.name + "': link " + std::to_string(l) +
                                        "'s parent must come before it");
        }
        link_of_[static_cast<std::size_t>(id)] = {c, static_cast<int>(l)};
        Body& b = bodies_[static_cast<std::size_t>(id)];
        setStatic(b);
        b.kinematic = true;
    }
    chains_.push_back(std::move(chain));
    ChainState state;
    state.clock = state.step_start = time_;
    chain_state_.push_back(state);
    poseChain(chains_.size() - 1, time_);
}

Real World::chainTime(std::size_t chain) const {
    CDLAB_ASSERT(chain < chain_state_.size(), "chain index out of range");
    return chain_state_[chain].clock;
}

bool World::chainHalted(std::size_t chain) const {
    CDLAB_ASSERT(chain < chain_state_.size(), "chain index out of range");
    return chain_state_[chain].halted;
}

bool World::pairAllowed(BodyId a, BodyId b) const {
    const auto ua = static_cast<std::size_t>(a);
    const auto ub = static_cast<std::size_t>(b);
    if (ua >= link_of_.size() || ub >= link_of_.size()) return true;
    const LinkOf la = link_of_[ua];
    const LinkOf lb = link_of_[ub];
    if (la.chain < 0 || la.chain != lb.chain) return true;
    const ChainSpec& c = chains_[static_cast<std::size_t>(la.chain)];
    if (c.collide_adjacent) return true;
    return c.chain.joints[static_cast<std::size_t>(la.link)].parent != lb.link &&
           c.chain.joints[static_cast<std::size_t>(lb.link)].parent != la.link;
}

void World::poseChain(std::size_t c, Real t) {
    const ChainSpec& spec = chains_[c];
    collision::chainFrames(spec.chain, t, frames_);
    for (std::size_t l = 0; l < spec.links.size(); ++l) {
        Body& b = bodies_[static_cast<std::size_t>(spec.links[l])];
        const Pose p = frames_[l] * spec.shape_in_link[l];
        b.position = p.position;
        b.orientation = p.orientation;
    }
}

// After integration: every running chain's clock to the step's end, its links posed there.
void World::moveChains() {
    for (std::size_t c = 0; c < chains_.size(); ++c) {
        ChainState& s = chain_state_[c];
        s.step_start = s.clock;
        s.moved = !s.halted;
        if (s.halted) continue;
        s.clock = time_;
        poseChain(c, s.clock);
    }
}

void World::dropExcludedPairs(std::vector<collision::ProxyPair>& pairs) const {
    pairs.erase(std::remove_if(pairs.begin(), pairs.end(),
                               [this](const collision::ProxyPair& p) {
                                   return !pairAllowed(static_cast<BodyId>(p.a),
                                                       static_cast<BodyId>(p.b));
                               }),
                pairs.end());
}

// A link of a chain that moved in this step: its conservative swept bounds from the joint
// motion over [step_start, clock]; a halted chain's link stays as buildSweeps made it (static).
void World::sweepLink(std::size_t i, SweptBody& s) const {
    const LinkOf l = link_of_[i];
    const ChainState& st = chain_state_[static_cast<std::size_t>(l.chain)];
    if (!st.moved) return;
    s.box = collision::linkSweptBounds(chains_[static_cast<std::size_t>(l.chain)].chain, l.link,
                                       st.step_start, st.clock);
    s.moving = true;
}

Vec3 World::linkPointVelocity(BodyId id, const Vec3& point, Real s) const {
    const auto i = static_cast<std::size_t>(id);
    if (i >= link_of_.size() || link_of_[i].chain < 0) return Vec3::Zero();
    const LinkOf l = link_of_[i];
    const ChainState& st = chain_state_[static_cast<std::size_t>(l.chain)];
    if (!st.moved) return Vec3::Zero();
    const collision::Chain& chain = chains_[static_cast<std::size_t>(l.chain)].chain;
    const Real span = st.clock - st.step_start;
    const Real t = st.step_start + s * span;
    const Real h = kVelocityStepFraction * span;
    collision::chainFrames(chain, t, frames_);
    const Vec3 local = frames_[static_cast<std::size_t>(l.link)].applyInverse(point);
    collision::chainFrames(chain, t + h, frames2_);
    const Vec3 ahead = frames2_[static_cast<std::size_t>(l.link)].apply(local);
    collision::chainFrames(chain, t - h, frames2_);
    const Vec3 behind = frames2_[static_cast<std::size_t>(l.link)].apply(local);
    return (ahead - behind) / (2 * h);
}

// One pair with a link: the articulated conservative advancement. A link of a chain that moved
// is a chain side; anything else (a halted chain's link, a rigid body) a rigid side with the
// sweep buildSweeps made. Acceptance as for rigid pairs (world_continuous.cpp).
void World::queryLinkImpact(const collision::ProxyPair& pair) {
    collision::ArticulatedToiInput in;
    Real t0 = 0;
    Real t1 = 0;
    bool timed = false;
    auto side = [&](BodyId id) {
        const auto i = static_cast<std::size_t>(id);
        collision::ArticulatedSide s;
        s.shape = &bodies_[i].shape;
        s.sweep = swept_[i].sweep;
        if (i < link_of_.size() && link_of_[i].chain >= 0) {
            const LinkOf l = link_of_[i];
            const ChainState& st = chain_state_[static_cast<std::size_t>(l.chain)];
            if (st.moved) {
                const ChainSpec& spec = chains_[static_cast<std::size_t>(l.chain)];
                s.chain = &spec.chain;
                s.link = l.link;
                s.shape_in_link = spec.shape_in_link[static_cast<std::size_t>(l.link)];
                // Running chains all share the step's interval [previous time, time()].
                t0 = st.step_start;
                t1 = st.clock;
                timed = true;
            }
        }
        return s;
    };
    in.side_a = side(pair.a);
    in.side_b = side(pair.b);
    if (!timed) return;  // neither link moves: nothing for the continuous stage
    in.t0 = t0;
    in.t1 = t1;
    in.target_gap =
        settings_.ccd_target_gap * std::min(swept_[pair.a].radius, swept_[pair.b].radius);
    in.relative_tolerance = settings_.ccd_tolerance;
    in.max_iterations = kLinkMaxIterations;
    // A deforming body's surface moves in its own frame as well (links never deform).
    in.deform_speed_a = swept_[pair.a].deform_speed;
    in.deform_speed_b = swept_[pair.b].deform_speed;
    const collision::ToiOutput out =
        askTimeOfImpact(in, stats_, [&] { return collision::timeOfImpactArticulated(in); });
    if (out.state != collision::CcdState::Hit && out.state != collision::CcdState::Failed) return;
    auto poseAt = [&](const collision::ArticulatedSide& s) {
        if (s.chain == nullptr) return s.sweep.at(out.t);
        collision::chainFrames(*s.chain, t0 + out.t * (t1 - t0), frames_);
        return frames_[static_cast<std::size_t>(s.link)] * s.shape_in_link;
    };
    const Pose pose_a = poseAt(in.side_a);
    const ToiEvent e = impactEvent(pair, out, pose_a, poseAt(in.side_b));
    if (e.t == 0) {
        // At the start of the step only an approaching pair is stopped (as rigid pairs).
        const Body& a = bodies_[pair.a];
        const Body& b = bodies_[pair.b];
        const Vec3 va = a.velocity() + a.angularVelocity().cross(e.point - e.pose_a.position) +
                        linkPointVelocity(pair.a, e.point, 0);
        const Vec3 vb = b.velocity() + b.angularVelocity().cross(e.point - e.pose_b.position) +
                        linkPointVelocity(pair.b, e.point, 0);
        if (!((vb - va).dot(e.normal) < 0)) return;
    }
    toi_events_.push_back(e);
}

void World::drawChainSkeletons(collision::DebugDraw& draw, const collision::Color& color) const {
    for (std::size_t c = 0; c < chains_.size(); ++c) {
        const collision::Chain& chain = chains_[c].chain;
        collision::chainFrames(chain, chain_state_[c].clock, frames_);
        for (std::size_t l = 0; l < chain.joints.size(); ++l) {
            const int parent = chain.joints[l].parent;
            const Vec3 from = parent < 0 ? chain.base.position
                                         : frames_[static_cast<std::size_t>(parent)].position;
            const Vec3 to = frames_[l].position;
            if ((to - from).squaredNorm() > 0) draw.drawLine(from, to, color);
        }
    }
}

// on_impact: stop: a chain with events halts at the earliest (its clock and every link's pose
// at that time), and its links' later events are dropped: the chain never got there.
// on_impact: continue keeps its trajectory and every event.
void World::stopChainsAtImpacts() {
    for (std::size_t c = 0; c < chains_.size(); ++c) {
        ChainState& st = chain_state_[c];
        if (!st.moved || chains_[c].on_impact != ChainImpact::Stop) continue;
        Real earliest = 2;
        for (const ToiEvent& e : toi_events_) {
            for (const BodyId id : {e.a, e.b}) {
                const auto i = static_cast<std::size_t>(id);
                if (i < link_of_.size() && link_of_[i].chain == static_cast<int>(c)) {
                    earliest = std::min(earliest, e.t);
                }
            }
        }
        if (earliest > 1) continue;
        st.clock = st.step_start + earliest * (st.clock - st.step_start);
        st.halted = true;
        poseChain(c, st.clock);
        const auto later = [this, c, earliest](const ToiEvent& e) {
            if (!(e.t > earliest)) return false;
            for (const BodyId id : {e.a, e.b}) {
                const auto i = static_cast<std::size_t>(id);
                if (i < link_of_.size() && link_of_[i].chain == static_cast<int>(c)) return true;
            }
            return false;
        };
        toi_events_.erase(std::remove_if(toi_events_.begin(), toi_events_.end(), later),
                          toi_events_.end());
    }
}

}  // namespace engine
