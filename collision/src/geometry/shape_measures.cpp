// collision/src/geometry/shape_measures.cpp -- see shape_measures.h.
#include "geometry/shape_measures.h"

#include <cmath>

#include "narrowphase/gjk.h"

namespace collision {

Real hullBoundingRadius(const Shape& shape) {
    return ConvexCore::fromShape(shape).boundingRadius();
}

}  // namespace collision
