// engine/src/repeat_placement.cpp -- SeparatedPlacement: rejection tests against a uniform grid.
#include "repeat_placement.h"

#include <algorithm>
#include <cmath>

namespace engine::scene_parsing {

namespace {

// Cells per axis at most: a radius tiny against the region makes cells larger than 2 r (still
// correct, as a candidate is tested against whole neighbouring cells), not an unbounded index.
constexpr Real kMaxCellsPerAxis = Real(1) * (std::int64_t(1) << 40);

// A fixed body whose box covers more cells than this is tested against every candidate instead.
constexpr std::int64_t kMaxCellsPerFixedBody = 64;

}  // namespace

std::size_t SeparatedPlacement::CellHash::operator()(const Cell& c) const {
    std::uint64_t h = 0x9E3779B97F4A7C15ull;
    for (const std::int64_t v : c) {
        h ^= static_cast<std::uint64_t>(v) + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    }
    return static_cast<std::size_t>(h);
}

SeparatedPlacement::SeparatedPlacement(const std::vector<Body>& existing, Real radius,
                                       const collision::Aabb& region)
    : radius_(radius), origin_(region.min - Vec3::Constant(radius)) {
    const Real extent = (region.max - region.min).maxCoeff() + 2 * radius;
    cell_ = std::max(2 * radius, extent / kMaxCellsPerAxis);
    if (!(cell_ > 0)) cell_ = 1;  // point bodies in a point region
    for (const Body& b : existing) {
        const collision::Pose pose{b.position, b.orientation};
        const collision::BoundingSphere w = collision::transformSphere(b.local_bounds.sphere, pose);
        const Fixed f{{w.center, w.radius}, collision::transformObb(b.local_bounds.obb, pose)};
        const Vec3 reach = Vec3::Constant(f.sphere.radius + radius);
        if (((f.sphere.centre + reach).array() < region.min.array()).any() ||
            ((f.sphere.centre - reach).array() > region.max.array()).any()) {
            continue;  // no centre in the region can come near it
        }
        insertFixed(f);
    }
}

std::int64_t SeparatedPlacement::cellIndex(Real coordinate, int axis) const {
    const Real t = std::floor((coordinate - origin_[axis]) / cell_);
    return static_cast<std::int64_t>(std::clamp(t, Real(-1), kMaxCellsPerAxis + 1));
}

void SeparatedPlacement::insertFixed(const Fixed& f) {
    const std::size_t id = fixed_.size();
    fixed_.push_back(f);
    // A candidate is refused only when it meets both volumes, so within the OBB's axis-aligned
    // box grown by the radius: indexing the cells of that box suffices (neighbours add the growth).
    const Vec3 reach = f.obb.axes.cwiseAbs() * f.obb.half_extents;
    const Vec3& centre = f.obb.center;
    Cell lo, hi;
    std::int64_t cells = 1;
    for (int k = 0; k < 3; ++k) {
        lo[k] = cellIndex(centre[k] - reach[k], k);
        hi[k] = cellIndex(centre[k] + reach[k], k);
        cells *= hi[k] - lo[k] + 1;
        if (cells > kMaxCellsPerFixedBody) break;
    }
    if (cells > kMaxCellsPerFixedBody) {
        large_.push_back(id);
        return;
    }
    for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
        for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
            for (std::int64_t z = lo[2]; z <= hi[2]; ++z) fixed_cells_[{x, y, z}].push_back(id);
}

bool SeparatedPlacement::apart(const Sphere& a, const Sphere& b) {
    const Real reach = a.radius + b.radius;
    return (a.centre - b.centre).squaredNorm() > reach * reach;
}

bool SeparatedPlacement::apart(const Sphere& a, const Fixed& f) {
    if (apart(a, f.sphere)) return true;
    // Distance from the centre to the box: clamp its coordinates in the box frame (RTCD 5.1.4).
    const Vec3 local = f.obb.axes.transpose() * (a.centre - f.obb.center);
    const Vec3 outside = (local.cwiseAbs() - f.obb.half_extents).cwiseMax(Real(0));
    return outside.squaredNorm() > a.radius * a.radius;
}

bool SeparatedPlacement::fits(const Vec3& centre) const {
    // Cells are at least 2 r wide, so a sphere of radius r centred in cell c meets only spheres
    // indexed in c and its 26 neighbours.
    const Sphere candidate{centre, radius_};
    for (const std::size_t id : large_) {
        if (!apart(candidate, fixed_[id])) return false;
    }
    const Cell c{cellIndex(centre[0], 0), cellIndex(centre[1], 1), cellIndex(centre[2], 2)};
    for (std::int64_t dx = -1; dx <= 1; ++dx)
        for (std::int64_t dy = -1; dy <= 1; ++dy)
            for (std::int64_t dz = -1; dz <= 1; ++dz) {
                const Cell n{c[0] + dx, c[1] + dy, c[2] + dz};
                if (const auto it = cells_.find(n); it != cells_.end()) {
                    for (const std::size_t id : it->second) {
                        if (!apart(candidate, spheres_[id])) return false;
                    }
                }
                if (const auto it = fixed_cells_.find(n); it != fixed_cells_.end()) {
                    for (const std::size_t id : it->second) {
                        if (!apart(candidate, fixed_[id])) return false;
                    }
                }
            }
    return true;
}

void SeparatedPlacement::add(const Vec3& centre) {
    const Cell c{cellIndex(centre[0], 0), cellIndex(centre[1], 1), cellIndex(centre[2], 2)};
    cells_[c].push_back(spheres_.size());
    spheres_.push_back({centre, radius_});
}

}  // namespace engine::scene_parsing
