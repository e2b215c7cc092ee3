// collision/visibility_oracle.h -- the seam through which the `cullide` broad phase
// asks a rasteriser which boxes are fully visible. collision defines it; render implements it
// with OpenGL occlusion queries on its OSMesa context; the app installs that implementation.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <stdexcept>

#include "collision/volumes/bounding_volumes.h"

namespace collision {

/// Renders axis-aligned boxes orthographically and answers full-visibility queries
/// (Govindaraju, Redon, Lin, Manocha, "CULLIDE", Graphics Hardware 2003, §4).
class VisibilityOracle {
public:
    virtual ~VisibilityOracle() = default;

    /// Pixels per side of the square view the oracle renders into (its footprint is what the
    /// caller fattens the boxes by).
    virtual int resolution() const = 0;

    /// Boxes in normalised device coordinates, inside [-1, 1]^3. The view looks along `axis`
    /// (0, 1, 2); screen u, v are the axes (axis+1)%3, (axis+2)%3, depth is `axis`, nearer is
    /// smaller. Draws the boxes in order 0..n-1 into a cleared depth buffer and sets
    /// `visible[i]` to 1 when no pixel centre of box i's far face lies at or behind the nearest
    /// face of a box drawn before it (box i is fully visible with respect to boxes 0..i-1),
    /// else 0. Pixel centres are sampled as OpenGL rasterises polygons.
    virtual void fullyVisibleInOrder(std::span<const Aabb> boxes, int axis,
                                     std::span<char> visible) = 0;
};

/// Where `cullide` gets its oracle. Empty until a module that can render installs one.
using VisibilityOracleFactory = std::function<std::unique_ptr<VisibilityOracle>()>;

/// Installs (or, with an empty function, removes) the process-wide oracle factory.
void setVisibilityOracleFactory(VisibilityOracleFactory factory);
/// True when a factory is installed.
bool hasVisibilityOracleFactory();

/// Thrown when a broad phase that needs a rendering context is created without one.
struct BroadPhaseUnavailable : std::runtime_error {
    using std::runtime_error::runtime_error;
};

}  // namespace collision
