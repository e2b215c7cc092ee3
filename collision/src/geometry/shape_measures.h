// collision/src/geometry/shape_measures.h -- what the narrow phase, contact() and the half-space
// queries share about shapes: their length scale, whether an input is usable at all, and the
// canonical order in which a pair is computed.
#pragma once

#include "collision/geometry/shape.h"

namespace collision {

/// Largest distance of the shape from its local origin: the length scale of its coordinates
/// (tolerances are relative to it). Hulls and meshes use their hull's farthest vertex.
Real boundingRadius(const Shape& shape);

/// True when the shape's dimensions and the pose are finite (NaN or inf anywhere makes the
/// query's answer Failed).
bool isFinite(const Shape& shape, const Pose& pose);

/// A strict order on (shape, pose): by type, then by a key of pose and dimensions, then by the
/// hull's and the mesh's addresses (equal keys and addresses mean identical inputs, where the
/// order does not matter). collide() and contact() compute every pair with the lesser first,
/// so (a, b) and (b, a) are the same computation mirrored.
bool canonicalLess(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b);

}  // namespace collision
