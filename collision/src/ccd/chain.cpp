// collision/src/ccd/chain.cpp -- articulated chains: joint trajectories, forward kinematics and
// the per-link motion bounds that the articulated time of impact (articulated.cpp) advances by.
//
// Invariant: every bound here is conservative, rounding included. range() contains every value
// at() returns on the interval, maxRate() is never below |dq/dt| on it, linkSpeedBound() never
// below the speed of a point of the link, linkSweptBounds() contains the link at every time.
//
// The speed bound (Zhang, Redon, Lee, Kim, "Continuous collision detection for articulated
// models using Taylor models and temporal culling", SIGGRAPH 2007, §4: motion bounds composed
// link to link; the rigid bound is Mirtich's, "Impulse-based dynamic simulation of rigid body
// systems", PhD thesis, UC Berkeley 1996). The base is fixed, so a point p of link m moves at
//     v(p) = sum over joints j on the path base -> m of
//            qdot_j a_j x (p - o_j)   (revolute j: a_j its world axis, o_j a point of the axis)
//            qdot_j a_j               (prismatic j)
// (the columns of the chain's Jacobian). With |a_j| = 1, |v(p)| <= sum |qdot_j| |p - o_j| over
// the revolute joints plus sum |qdot_j| over the prismatic ones. Take o_j the origin of joint
// j's frame: link j's frame origin is o_j (revolute, fixed) or o_j + q_j a_j (prismatic), and
// o_{k} sits at offset origin_k.position from link parent(k)'s frame origin. So by the
// triangle inequality, for p within link_radius[m] of link m's origin,
//     |p - o_j| <= link_radius[m] + sum over path joints k after j of |origin_k.position|
//                  + sum over prismatic path joints k >= j of max |q_k| on the interval,
// the bound linkSpeedBound() accumulates walking from the link towards the base.
#include "collision/ccd/chain.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "collision/assert.h"

namespace collision {

namespace {

constexpr Real kTwoPi = 2 * kPi;
constexpr Real kHalfPi = kPi / 2;

// Rounding allowances, in units of kEpsilon times the magnitude they apply to: a handful of
// roundings per evaluated expression, doubled.
constexpr Real kRoundingUlps = 8;

// The sine's phase angle at t. at(), range() and maxRate() all compute it this one way:
// fl(fl(w t) + phase) is monotone in t, so the angles of the times of [t0, t1] lie between
// the angles of t0 and t1.
Real sineAngle(const JointTrajectory& q, Real t) {
    const Real w = kTwoPi * q.frequency;
    return w * t + q.phase;
}

// Does some angle c + k period (k integer) lie in [lo, hi], widened by the rounding of the
// angles? Widening only reports more extrema: conservative.
bool containsLattice(Real lo, Real hi, Real c, Real period) {
    const Real slack = kRoundingUlps * kEpsilon * (std::abs(lo) + std::abs(hi) + 1);
    const Real k = std::ceil((lo - slack - c) / period);
    return c + k * period <= hi + slack;
}

// The angles of the ends of [t0, t1], in increasing order.
std::pair<Real, Real> sineAngles(const JointTrajectory& q, Real t0, Real t1) {
    const Real a = sineAngle(q, t0);
    const Real b = sineAngle(q, t1);
    return {std::min(a, b), std::max(a, b)};
}

std::pair<Real, Real> sineRange(const JointTrajectory& q, Real t0, Real t1) {
    const auto [lo, hi] = sineAngles(q, t0, t1);
    Real s_lo = -1;
    Real s_hi = 1;
    if (hi - lo < kTwoPi) {
        const Real sa = std::sin(lo);
        const Real sb = std::sin(hi);
        const Real pad = kRoundingUlps * kEpsilon;
        s_lo = containsLattice(lo, hi, -kHalfPi, kTwoPi) ? Real(-1) : std::min(sa, sb) - pad;
        s_hi = containsLattice(lo, hi, kHalfPi, kTwoPi) ? Real(1) : std::max(sa, sb) + pad;
    }
    const Real a_lo = std::min(q.amplitude * s_lo, q.amplitude * s_hi);
    const Real a_hi = std::max(q.amplitude * s_lo, q.amplitude * s_hi);
    const Real pad = kRoundingUlps * kEpsilon * (std::abs(q.value) + std::abs(q.amplitude));
    return {q.value + a_lo - pad, q.value + a_hi + pad};
}

Real sineMaxRate(const JointTrajectory& q, Real t0, Real t1) {
    const Real peak = std::abs(q.amplitude * kTwoPi * q.frequency);
    if (peak == 0) return 0;
    const auto [lo, hi] = sineAngles(q, t0, t1);
    Real c = 1;  // largest |cos| over [lo, hi]: 1 where a multiple of pi lies inside
    if (hi - lo < kPi && !containsLattice(lo, hi, 0, kPi)) {
        // |cos| is 1-Lipschitz: the angles' own rounding error adds at most that much.
        const Real slack = kRoundingUlps * kEpsilon * (std::abs(lo) + std::abs(hi) + 1);
        c = std::min(Real(1), std::max(std::abs(std::cos(lo)), std::abs(std::cos(hi))) + slack);
    }
    return peak * c * (1 + kRoundingUlps * kEpsilon);
}

// Index k of the keyframe segment [keys[k], keys[k+1]] that holds t, for t strictly inside
// the keys' span; clamped to a valid segment whatever the keys' order (no out-of-range read).
std::size_t keySegment(const std::vector<std::pair<Real, Real>>& keys, Real t) {
    const auto it =
        std::upper_bound(keys.begin(), keys.end(), t,
                         [](Real x, const std::pair<Real, Real>& k) { return x < k.first; });
    const std::size_t i = static_cast<std::size_t>(it - keys.begin());
    return std::clamp<std::size_t>(i, 1, keys.size() - 1) - 1;
}

// First segment whose end time is >= t (segments before it end before t).
std::size_t firstSegmentFrom(const std::vector<std::pair<Real, Real>>& keys, Real t) {
    const auto it =
        std::lower_bound(keys.begin(), keys.end(), t,
                         [](const std::pair<Real, Real>& k, Real x) { return k.first < x; });
    const std::size_t i = static_cast<std::size_t>(it - keys.begin());
    return i == 0 ? 0 : i - 1;
}

std::pair<Real, Real> keyframeRange(const JointTrajectory& q, Real t0, Real t1) {
    Real lo = std::min(q.at(t0), q.at(t1));
    Real hi = std::max(q.at(t0), q.at(t1));
    const auto& keys = q.keys;
    for (std::size_t k = firstSegmentFrom(keys, t0); k < keys.size() && keys[k].first <= t1; ++k) {
        if (keys[k].first >= t0) {
            lo = std::min(lo, keys[k].second);
            hi = std::max(hi, keys[k].second);
        }
    }
    // Interpolation va + (vb - va) f rounds within a few ulps of the larger key value.
    const Real pad = kRoundingUlps * kEpsilon * std::max(std::abs(lo), std::abs(hi));
    return {lo - pad, hi + pad};
}

Real keyframeMaxRate(const JointTrajectory& q, Real t0, Real t1) {
    const auto& keys = q.keys;
    Real rate = 0;
    // Every segment that touches the closed interval: at a key time the slope may be either.
    for (std::size_t k = firstSegmentFrom(keys, t0); k + 1 < keys.size() && keys[k].first <= t1;
         ++k) {
        const Real dt = keys[k + 1].first - keys[k].first;
        const Real dq = std::abs(keys[k + 1].second - keys[k].second);
        CDLAB_ASSERT(dt > 0, "keyframe times must be strictly increasing");
        rate = std::max(rate, dt > 0 ? dq / dt : std::numeric_limits<Real>::infinity());
    }
    return rate * (1 + kRoundingUlps * kEpsilon);
}

// Joint i's motion J(q): a turn about or a slide along its (normalised) axis.
Pose jointMotion(const ChainJoint& joint, Real q) {
    Pose m;
    const Real len = joint.axis.norm();
    if (joint.type == JointType::Fixed || !(len > 0)) return m;
    const Vec3 axis = joint.axis / len;
    if (joint.type == JointType::Revolute) {
        m.orientation = Quat(Eigen::AngleAxis<Real>(q, axis));
    } else {
        m.position = q * axis;
    }
    return m;
}

// Parent index of joint i, or -1 for the base (also for a malformed parent >= i, after the
// assertion: the walk towards the base must strictly decrease, so it always ends).
int parentOf(const Chain& chain, int i) {
    const int p = chain.joints[static_cast<std::size_t>(i)].parent;
    CDLAB_ASSERT(p < i && p >= -1, "a link's parent must come before it");
    return p >= 0 && p < i ? p : -1;
}

// Frame of link i at t, composed recursively along its path from `root` (the base frame, or
// the base frame shifted to another origin) without allocation.
Pose frameOf(const Chain& chain, const Pose& root, int i, Real t) {
    const ChainJoint& j = chain.joints[static_cast<std::size_t>(i)];
    const int p = parentOf(chain, i);
    const Pose parent = p < 0 ? root : frameOf(chain, root, p, t);
    Pose f = parent * j.origin * jointMotion(j, j.trajectory.at(t));
    f.orientation.normalize();
    return f;
}

// Walk from `link` to the base: the speed bound (m/s) and the reach (a bound on the distance
// from the base origin to any point of the link) over [t0, t1], and the path length.
struct PathBound {
    Real speed = 0;
    Real reach = 0;
    int length = 0;
};

PathBound walkPath(const Chain& chain, int link, Real reach, Real t0, Real t1) {
    PathBound b;
    b.reach = reach;
    for (int i = link; i >= 0; i = parentOf(chain, i)) {
        const ChainJoint& j = chain.joints[static_cast<std::size_t>(i)];
        // `reach` bounds |p - origin of link i|.
        if (j.type == JointType::Prismatic) {
            const auto [lo, hi] = j.trajectory.range(t0, t1);
            b.speed += j.trajectory.maxRate(t0, t1);
            b.reach += std::max(std::abs(lo), std::abs(hi));  // now bounds |p - o_i|
        } else if (j.type == JointType::Revolute) {
            b.speed += j.trajectory.maxRate(t0, t1) * b.reach;  // o_i is link i's origin
        }
        b.reach += j.origin.position.norm();  // now bounds |p - origin of the parent link|
        ++b.length;
    }
    // A sum of `length` non-negative terms, each a product of two rounded factors.
    const Real slack = 1 + kRoundingUlps * kEpsilon * Real(b.length + 1);
    b.speed *= slack;
    b.reach *= slack;
    return b;
}

bool validLink(const Chain& chain, int link) {
    const bool ok = link >= 0 && static_cast<std::size_t>(link) < chain.joints.size() &&
                    chain.link_radius.size() == chain.joints.size();
    CDLAB_ASSERT(ok, "link index out of range or link_radius not one per link");
    return ok;
}

}  // namespace

Real JointTrajectory::at(Real t) const {
    switch (kind) {
        case Kind::Constant:
            return value;
        case Kind::Ramp:
            return value + rate * t;
        case Kind::Sine:
            return value + amplitude * std::sin(sineAngle(*this, t));
        case Kind::Keyframes: {
            if (keys.empty()) return value;
            // Held before the first key and after the last (NaN t: the first key's value).
            if (!(t > keys.front().first)) return keys.front().second;
            if (!(t < keys.back().first)) return keys.back().second;
            const std::size_t k = keySegment(keys, t);
            const auto& [ta, va] = keys[k];
            const auto& [tb, vb] = keys[k + 1];
            const Real f = std::clamp((t - ta) / (tb - ta), Real(0), Real(1));
            return va + (vb - va) * f;
        }
    }
    return value;
}

Real JointTrajectory::maxRate(Real t0, Real t1) const {
    if (t0 > t1) std::swap(t0, t1);
    switch (kind) {
        case Kind::Constant:
            return 0;
        case Kind::Ramp:
            return std::abs(rate);
        case Kind::Sine:
            return sineMaxRate(*this, t0, t1);
        case Kind::Keyframes:
            return keyframeMaxRate(*this, t0, t1);
    }
    return 0;
}

std::pair<Real, Real> JointTrajectory::range(Real t0, Real t1) const {
    if (t0 > t1) std::swap(t0, t1);
    switch (kind) {
        case Kind::Constant:
            return {value, value};
        case Kind::Ramp: {
            // fl(value + fl(rate t)) is monotone in t: the ends bound every time between.
            const Real a = at(t0);
            const Real b = at(t1);
            return {std::min(a, b), std::max(a, b)};
        }
        case Kind::Sine:
            return sineRange(*this, t0, t1);
        case Kind::Keyframes:
            return keyframeRange(*this, t0, t1);
    }
    return {value, value};
}

void chainFrames(const Chain& chain, Real t, std::vector<Pose>& out) {
    out.resize(chain.joints.size());
    for (std::size_t i = 0; i < chain.joints.size(); ++i) {
        const ChainJoint& j = chain.joints[i];
        const int p = parentOf(chain, static_cast<int>(i));
        const Pose& parent = p < 0 ? chain.base : out[static_cast<std::size_t>(p)];
        out[i] = parent * j.origin * jointMotion(j, j.trajectory.at(t));
        out[i].orientation.normalize();
    }
}

Pose linkFrame(const Chain& chain, int link, Real t) {
    if (link < 0 || static_cast<std::size_t>(link) >= chain.joints.size()) {
        CDLAB_ASSERT(false, "link index out of range");
        return chain.base;
    }
    return frameOf(chain, chain.base, link, t);
}

Pose linkFrame(const Chain& chain, int link, Real t, const Vec3& origin) {
    const Pose root{chain.base.position - origin, chain.base.orientation};
    if (link < 0 || static_cast<std::size_t>(link) >= chain.joints.size()) {
        CDLAB_ASSERT(false, "link index out of range");
        return root;
    }
    return frameOf(chain, root, link, t);
}

Real linkSpeedBound(const Chain& chain, int link, Real t0, Real t1) {
    if (!validLink(chain, link)) return std::numeric_limits<Real>::infinity();
    return walkPath(chain, link, chain.link_radius[static_cast<std::size_t>(link)], t0, t1).speed;
}

Real linkPointSpeedBound(const Chain& chain, int link, Real reach, Real t0, Real t1) {
    if (link < 0 || static_cast<std::size_t>(link) >= chain.joints.size()) {
        CDLAB_ASSERT(false, "link index out of range");
        return std::numeric_limits<Real>::infinity();
    }
    return walkPath(chain, link, reach, t0, t1).speed;
}

Aabb linkSweptBounds(const Chain& chain, int link, Real t0, Real t1) {
    if (!validLink(chain, link)) {
        const Real inf = std::numeric_limits<Real>::infinity();
        return Aabb{Vec3::Constant(-inf), Vec3::Constant(inf)};
    }
    const Real radius = chain.link_radius[static_cast<std::size_t>(link)];
    const PathBound b = walkPath(chain, link, radius, t0, t1);
    const Vec3 centre = frameOf(chain, chain.base, link, Real(0.5) * (t0 + t1)).position;
    // Every point is within link_radius of the origin, which moves at most speed |t - tm|
    // from its place at the middle time tm. Pad: the rounding of forward kinematics, a few ulps
    // per joint of the largest coordinate involved.
    const Real travel = Real(0.5) * std::abs(t1 - t0) * b.speed;
    const Real pad = kRoundingUlps * kEpsilon * Real(b.length + 1) *
                     (chain.base.position.norm() + b.reach + travel);
    const Real half = travel + radius + pad;
    return Aabb{centre - Vec3::Constant(half), centre + Vec3::Constant(half)};
}

}  // namespace collision
