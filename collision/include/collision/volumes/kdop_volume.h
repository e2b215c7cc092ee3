// collision/volumes/kdop_volume.h -- a body's world k-DOP (k = 6, 14, 18, 26) as a per-body
// bounding volume, its slab overlap test, and the polytope it bounds (the intersection of its
// slabs) as vertices and edges for drawing. Klosowski, Held, Mitchell, Sowizral, Zikan 1998,
// "Efficient collision detection using bounding volume hierarchies of k-DOPs"; RTCD 4.6.
#pragma once

#include <array>
#include <vector>

#include "collision/math.h"

namespace collision {

struct Shape;

/// A world-frame k-DOP: slab i is { p : min[i] <= dot(kdopSlabDirection(k, i), p) <= max[i] }
/// for i < k / 2; the entries past k / 2 are unused.
struct WorldKdop {
    int k = 6;
    std::array<Real, 13> min{};
    std::array<Real, 13> max{};

    /// Closed slab test on every shared direction (both k-DOPs must have the same k): touching
    /// slabs overlap. Conservative: k-DOPs apart on no slab may still have disjoint polytopes.
    bool overlaps(const WorldKdop& o) const;
};

/// True for k = 6, 14, 18, 26.
bool isKdopK(int k);

/// Direction of slab `i` (0 <= i < k / 2), unnormalised with integer components, the same set
/// the mesh BVH's Kdop<K> uses: the axes; + the 4 cube diagonals (14, 26); + the 6 face
/// diagonals (18, 26).
Vec3 kdopSlabDirection(int k, int i);

/// The tight world k-DOP of `shape` at `pose`: each slab the exact support of the shape along
/// its direction and the opposite one (supportPoint; the hull's for meshes). k must be valid.
WorldKdop computeWorldKdop(const Shape& shape, const Pose& pose, int k);

/// Vertices and edges of a convex polytope (indices into `vertices`, each edge once).
struct KdopPolytope {
    std::vector<Vec3> vertices;
    std::vector<std::array<int, 2>> edges;
};

/// The polytope { p : min[i] <= dot(d_i, p) <= max[i] } of the k-DOP: the box of the three axis
/// slabs clipped by the other slabs' half-spaces, face by face (Sutherland-Hodgman, RTCD 8.3.4),
/// each cut closing the polytope with its cap face. Vertices closer than a tolerance relative
/// to the k-DOP's size are welded. Flat k-DOPs (a zero-thickness slab) give a flat or lower-
/// dimensional polytope without NaNs. Every vertex satisfies every half-space to within
/// kdopPolytopeTolerance. O(k^2) per polytope.
KdopPolytope kdopPolytope(const WorldKdop& kdop);

/// The tolerance kdopPolytope guarantees (scene units): a few hundred ulps of the k-DOP's
/// largest coordinate, so a k-DOP far from the origin is as exact as one at it.
Real kdopPolytopeTolerance(const WorldKdop& kdop);

}  // namespace collision
