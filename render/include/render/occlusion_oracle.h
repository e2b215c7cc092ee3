// render/occlusion_oracle.h -- the visibility oracle of the `cullide` broad phase, implemented
// with OpenGL occlusion queries (GL 1.5 / ARB_occlusion_query) on an OSMesa context.
#pragma once

#include <memory>

#include "collision/visibility_oracle.h"

namespace render {

/// A square off-screen view of `resolution` pixels per side with its own OSMesa context.
/// Throws collision::BroadPhaseUnavailable when no context can be made or it has no occlusion
/// queries.
std::unique_ptr<collision::VisibilityOracle> makeOcclusionQueryOracle(int resolution = 512);

/// Installs makeOcclusionQueryOracle as the process's oracle factory, so that the registry's
/// `cullide` can be created.
void installOcclusionQueryOracle();

}  // namespace render
