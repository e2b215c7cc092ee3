// engine/mass_properties.h -- mass, centre of mass and inertia of each shape from its density.
// Polyhedra use the volume integrals of Mirtich, "Fast and Accurate Computation of Polyhedral
// Mass Properties" (JGT 1996), via the divergence theorem over the boundary triangles.
#pragma once

#include <string>

#include "collision/geometry/shape.h"
#include "engine/body.h"

namespace engine {

struct MassPropertiesOutput {
    bool ok = false;
    std::string error;  ///< e.g. "mesh is not closed: volume <= 0"
    MassProperties props;
};

/// Mass properties of `shape` with uniform `density` (kg/m^3, > 0). Meshes must be closed and
/// outward oriented (their signed volume must be > 0); hulls always are.
MassPropertiesOutput computeMassProperties(const collision::Shape& shape, Real density);

/// Volume of the shape (m^3). Meshes: signed volume of the closed surface.
Real shapeVolume(const collision::Shape& shape);

}  // namespace engine
