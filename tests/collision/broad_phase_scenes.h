// tests/collision/broad_phase_scenes.h -- the moving-box scenes and registry rows shared by the
// broad-phase differential tests (broad_phase_test.cpp, broad_phase_insert_test.cpp; both also
// compiled into cullide_tests).
#pragma once

#include <cmath>
#include <memory>
#include <tuple>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "collision/visibility_oracle.h"
#include "test_random.h"

namespace cdlab_test {

using collision::Aabb;
using collision::BoundingSphere;
using collision::BroadPhase;
using collision::BroadPhaseEntry;
using collision::Mat3;
using collision::Obb;
using collision::ProxyVolumes;

// The registry rows this binary tests: with a visibility oracle installed (cullide_tests) the
// ones that need it, else (collision_tests, which cannot render) all the others.
inline std::vector<BroadPhaseEntry> testedBroadPhases() {
    std::vector<BroadPhaseEntry> out;
    for (const BroadPhaseEntry& e : collision::broadPhaseRegistry()) {
        if (e.needs_render_context == collision::hasVisibilityOracleFactory()) out.push_back(e);
    }
    return out;
}

// A moving box whose three volumes are consistent: exact AABB, circumsphere, the box as OBB.
struct MovingBox {
    Vec3 center;
    Vec3 velocity;
    Quat orientation;
    Quat spin;  // applied each frame
    Vec3 half_extents;
    bool present = true;

    ProxyVolumes volumes() const {
        const Mat3 r = orientation.toRotationMatrix();
        const Vec3 e = r.cwiseAbs() * half_extents;
        return ProxyVolumes{Aabb{center - e, center + e},
                            BoundingSphere{center, half_extents.norm()},
                            Obb{center, r, half_extents}};
    }
};

enum class Layout { Uniform, Clustered, MixedSizes, Coincident, FarFromOrigin, Lattice, ZeroSize };

inline const char* layoutName(Layout l) {
    switch (l) {
        case Layout::Uniform:
            return "uniform";
        case Layout::Clustered:
            return "clustered";
        case Layout::MixedSizes:
            return "mixed-sizes";
        case Layout::Coincident:
            return "coincident";
        case Layout::FarFromOrigin:
            return "far-from-origin";
        case Layout::Lattice:
            return "lattice-touching";
        case Layout::ZeroSize:
            return "zero-size";
    }
    return "?";
}

inline std::vector<MovingBox> makeScene(Layout layout, int n, Rng& rng) {
    std::vector<MovingBox> boxes;
    for (int i = 0; i < n; ++i) {
        MovingBox b;
        b.center = rng.vec(-10, 10);
        b.velocity = rng.vec(-0.2, 0.2);
        b.orientation = rng.rotation();
        b.spin = Quat(Eigen::AngleAxis<Real>(rng.uniform(0, 0.05), rng.vec(-1, 1).normalized()));
        b.half_extents = rng.vec(0.2, 1.0);
        switch (layout) {
            case Layout::Uniform:
                break;
            case Layout::Clustered:
                b.center = Vec3::Constant(rng.integer(0, 2) * 6.0) + rng.vec(-1.5, 1.5);
                break;
            case Layout::MixedSizes:
                // Size ratio 1:10^4.
                b.half_extents = Vec3::Constant(i % 7 == 0 ? 20.0 : 0.002) + rng.vec(0, 0.001);
                break;
            case Layout::Coincident:
                b.center = Vec3(1, 2, 3);
                b.velocity = Vec3::Zero();
                if (i % 2 == 0) b.spin = Quat::Identity();
                break;
            case Layout::FarFromOrigin:
                b.center += Vec3(1e6, -1e6, 1e6);
                break;
            case Layout::Lattice:
                // Unit cubes on a half-integer lattice, axis aligned, moving by exact binary
                // steps: faces, edges and corners touch exactly and often.
                b.center = Vec3(rng.integer(-6, 6), rng.integer(-6, 6), rng.integer(-6, 6)) * 0.5;
                b.velocity =
                    Vec3(rng.integer(-1, 1), rng.integer(-1, 1), rng.integer(-1, 1)) * 0.25;
                b.orientation = Quat::Identity();
                b.spin = Quat::Identity();
                b.half_extents = Vec3::Constant(0.5);
                break;
            case Layout::ZeroSize:
                if (i % 2 == 0) b.half_extents = Vec3::Zero();
                b.center = Vec3(rng.integer(-3, 3), rng.integer(-3, 3), rng.integer(-3, 3)) * 0.5;
                b.velocity = Vec3(rng.integer(-1, 1), 0, 0) * 0.5;
                b.orientation = Quat::Identity();
                b.spin = Quat::Identity();
                if (i % 2 == 1) b.half_extents = Vec3::Constant(0.5);
                break;
        }
        boxes.push_back(b);
    }
    return boxes;
}

inline void advance(std::vector<MovingBox>& boxes, Layout layout) {
    const Real limit = layout == Layout::Lattice || layout == Layout::ZeroSize ? 3 : 10;
    for (MovingBox& b : boxes) {
        b.center += b.velocity;
        b.orientation = (b.spin * b.orientation).normalized();
        const Vec3 base = layout == Layout::FarFromOrigin ? Vec3(1e6, -1e6, 1e6) : Vec3::Zero();
        for (int k = 0; k < 3; ++k) {
            if (std::abs(b.center[k] - base[k]) > limit) b.velocity[k] = -b.velocity[k];
        }
    }
}

// Two copies of a registry row, to be fed the same boxes two ways, and its brute-force
// reference (null when the registry has no row of the reference's name).
inline std::tuple<std::unique_ptr<BroadPhase>, std::unique_ptr<BroadPhase>,
                  std::unique_ptr<BroadPhase>>
twoCopiesAndReference(const BroadPhaseEntry& entry) {
    const BroadPhaseEntry* ref_entry = collision::findBroadPhase(entry.reference);
    return {entry.create(), entry.create(), ref_entry ? ref_entry->create() : nullptr};
}

}  // namespace cdlab_test
