// engine/src/repeat_placement.h -- where `repeat` may put a body so that it overlaps nothing
// already placed: bounding spheres about the centre of mass, looked up in a uniform grid.
#pragma once

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "engine/body.h"

namespace engine::scene_parsing {

/// Random sequential addition (rejection sampling) of equal bounding spheres among fixed bodies.
/// A candidate centre is accepted when its sphere of `radius` is strictly apart from every
/// sphere added before and, for each body given at construction, from its world bounding sphere
/// or its world OBB (either suffices: a floor's sphere is far larger than the floor).
/// Conservative: two bodies whose volumes overlap may not touch, so a region packed past about a
/// third of its volume (the jamming limit of random sequential addition of spheres, ~0.38) runs
/// out of room before it is full; the caller caps the attempts.
class SeparatedPlacement {
public:
    /// `existing`: bodies already in the scene (only those whose spheres can reach `region`
    /// grown by `radius` are kept); `radius`: the bounding radius of each body to be added.
    SeparatedPlacement(const std::vector<Body>& existing, Real radius, const collision::Aabb& region);

    bool fits(const Vec3& centre) const;
    void add(const Vec3& centre);

private:
    struct Sphere {
        Vec3 centre;
        Real radius;
    };
    struct Fixed {
        Sphere sphere;
        collision::Obb obb;
    };
    using Cell = std::array<std::int64_t, 3>;
    struct CellHash {
        std::size_t operator()(const Cell& c) const;
    };
    std::int64_t cellIndex(Real coordinate, int axis) const;
    void insertFixed(const Fixed& f);
    static bool apart(const Sphere& a, const Sphere& b);
    static bool apart(const Sphere& a, const Fixed& f);

    Real radius_;
    Real cell_;     ///< edge of a grid cell: twice the radius of the added spheres
    Vec3 origin_;   ///< grid corner: the region's minimum grown by the radius
    std::vector<Sphere> spheres_;     ///< added, each indexed in the cell of its centre
    std::vector<Fixed> fixed_;        ///< given, each indexed in every cell its OBB's box meets
    std::vector<std::size_t> large_;  ///< fixed bodies too big to index: tested every time
    std::unordered_map<Cell, std::vector<std::size_t>, CellHash> cells_;
    std::unordered_map<Cell, std::vector<std::size_t>, CellHash> fixed_cells_;
};

}  // namespace engine::scene_parsing
