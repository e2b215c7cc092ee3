// engine/src/world_records.h -- the World's private per-body records: a body's sweep over the
// step (the continuous stage's scratch), a link's place in its chain, a chain's clock, a
// deforming mesh body's own geometry. Private to the engine; world.h declares them only.
#pragma once

#include <memory>
#include <vector>

#include "collision/bvh/bvh.h"
#include "collision/ccd/ccd.h"
#include "collision/geometry/shape.h"
#include "engine/body.h"

namespace engine {

/// A body's sweep from its pose at the start of the step to its integrated pose (reused across
/// steps: no allocation once warm).
struct SweptBody {
    collision::Sweep sweep;
    collision::Aabb box;    ///< swept bounds over the step
    Real radius = 0;        ///< bounding radius about the centre of mass
    Real deform_speed = 0;  ///< m per step: deformation's bound on any point's speed
    Real clamp_t = 1;       ///< earliest accepted time of impact
    bool moving = false;
};

/// Which chain and link a body is (-1: none).
struct LinkOf {
    int chain = -1;
    int link = -1;
};

/// A chain's clock within its step.
struct ChainState {
    Real clock = 0;       ///< s, the time the links are posed at
    Real step_start = 0;  ///< s, the clock at the start of the step
    bool halted = false;
    bool moved = false;  ///< the clock advanced in this step
};

/// A deforming mesh body's own geometry: rest vertices, the current mesh and hierarchy (the
/// body's shape points at them), and the hierarchy's volume ratio at its last build.
struct DeformingMesh {
    BodyId body = 0;
    std::vector<Vec3> rest;
    std::shared_ptr<collision::TriangleMesh> mesh;
    std::shared_ptr<collision::MeshBvh> bvh;
    Real built_ratio = 0;
    Real speed_bound = 0;  ///< m/s, deformSpeedBound of the rest vertices
};

}  // namespace engine
