// collision/src/geometry/shape_measures.h -- measures of a shape that the narrow phase, contact()
// and the half-space queries share: its length scale and whether an input is usable at all.
#pragma once

#include "collision/geometry/shape.h"

namespace collision {

/// Largest distance of the shape from its local origin: the length scale of its coordinates
/// (tolerances are relative to it). Hulls and meshes use their hull's farthest vertex.
Real boundingRadius(const Shape& shape);

/// True when the shape's dimensions and the pose are finite (NaN or inf anywhere makes the
/// query's answer Failed).
bool isFinite(const Shape& shape, const Pose& pose);

}  // namespace collision
