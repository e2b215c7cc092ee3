// Must compile: the control case (a downward include), so the failures of the other layering
// checks are failures of layering, not of the set-up.
#include "collision/volumes/bounding_volumes.h"
#include "engine/world.h"
int layeringControl() { return collision::Aabb{}.overlaps(collision::Aabb{}) ? 0 : 1; }
