// engine/mass_properties.h -- mass, centre of mass and inertia of each shape from its density.
// Polyhedra use the volume integrals of Mirtich, "Fast and Accurate Computation of Polyhedral
// Mass Properties" (JGT 1996), via the divergence theorem over the boundary triangles.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

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

/// Edges of `triangles` that do not bound a closed surface: for each undirected edge, the
/// imbalance between its two directions (a 2-manifold's boundary edge counts 1, a closed
/// consistently oriented mesh has none). 0 <=> closed in the sense the volume integrals need.
/// O(n log n) in the triangle count.
std::int64_t boundaryEdgeCount(const std::vector<std::array<std::int32_t, 3>>& triangles);

/// Why `inertia` (kg m^2, about the centre of mass, in the body frame) cannot be a rigid
/// body's inertia tensor, or "" when it can: it must be finite, symmetric (to 1e-9 of its
/// largest entry), positive definite, and its principal moments must satisfy the triangle
/// inequality I1 <= I2 + I3 (to 1e-9 of the trace: a flat lamina has I1 = I2 + I3), since
/// every mass distribution does (Goldstein, Classical Mechanics, §5.3).
std::string inertiaProblem(const Mat3& inertia);

}  // namespace engine
