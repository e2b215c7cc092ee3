// tests/collision/test_chains.h -- fixed-seed random articulated chains (collision/ccd/chain.h)
// shared by the chain and articulated time-of-impact tests.
#pragma once

#include <cmath>
#include <utility>
#include <vector>

#include "collision/ccd/chain.h"
#include "test_random.h"

namespace cdlab_test {

/// A random trajectory for a joint whose values are angles (revolute) or lengths of order
/// `length` (prismatic); rates up to about `speed` units per second.
inline collision::JointTrajectory randomJointTrajectory(Rng& rng, collision::Real length,
                                                        collision::Real speed) {
    using collision::JointTrajectory;
    using collision::Real;
    JointTrajectory q;
    q.kind = static_cast<JointTrajectory::Kind>(rng.integer(0, 3));
    q.value = rng.uniform(-1, 1) * length;
    switch (q.kind) {
        case JointTrajectory::Kind::Constant:
            break;
        case JointTrajectory::Kind::Ramp:
            q.rate = rng.uniform(-1, 1) * speed;
            break;
        case JointTrajectory::Kind::Sine:
            q.amplitude = rng.uniform(-1, 1) * length;
            q.frequency = speed / (2 * Real(M_PI)) * rng.uniform(0, 1);
            q.phase = rng.uniform(-4, 4);
            break;
        case JointTrajectory::Kind::Keyframes: {
            Real t = rng.uniform(-1, 0.5);
            const int n = rng.integer(1, 8);
            for (int i = 0; i < n; ++i) {
                q.keys.emplace_back(t, rng.uniform(-1, 1) * length);
                t += rng.uniform(0.05, 0.5);
            }
            break;
        }
    }
    return q;
}

/// A random chain of `links` links of size about `scale` (m), joint speeds up to about `speed`
/// rad/s (prismatic: scale * speed m/s), its base `base_distance` from the world origin. Mostly
/// serial, with the odd branch (a parent further back than the previous link).
inline collision::Chain randomChain(Rng& rng, int links, collision::Real scale,
                                    collision::Real base_distance, collision::Real speed) {
    using collision::ChainJoint;
    using collision::JointType;
    using collision::Real;
    using collision::Vec3;
    collision::Chain chain;
    const Vec3 dir = rng.vec(-1, 1);
    chain.base.position = dir.norm() > 0 ? Vec3(dir.normalized() * base_distance) : Vec3::Zero();
    chain.base.orientation = rng.rotation();
    for (int i = 0; i < links; ++i) {
        ChainJoint j;
        const int kind = rng.integer(0, 9);
        j.type =
            kind < 5 ? JointType::Revolute : (kind < 8 ? JointType::Prismatic : JointType::Fixed);
        j.parent = i == 0 ? -1 : (rng.integer(0, 4) == 0 ? rng.integer(-1, i - 1) : i - 1);
        j.origin.position = rng.vec(-1, 1) * scale;
        j.origin.orientation = rng.rotation();
        const Vec3 axis = rng.vec(-1, 1);
        j.axis = axis.norm() > Real(0.1) ? Vec3(axis.normalized()) : Vec3::UnitZ();
        const Real length = j.type == JointType::Prismatic ? scale : Real(M_PI);
        const Real rate = j.type == JointType::Prismatic ? speed * scale : speed;
        j.trajectory = randomJointTrajectory(rng, length, rate);
        chain.joints.push_back(j);
        chain.link_radius.push_back(scale * rng.uniform(0.1, 1));
    }
    return chain;
}

}  // namespace cdlab_test
