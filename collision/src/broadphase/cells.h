// collision/src/broadphase/cells.h -- shared pieces of the cell-based broad phases (grid, hash,
// hierarchical grid): integer cell coordinates, a cell-key hash, and the cell-size estimate.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "broadphase/proxy_table.h"
#include "collision/math.h"

namespace collision {

/// Integer cell coordinates along each axis. 64-bit so that small cells far from the origin
/// (1e6 m / 1e-3 m) do not overflow. Range: every coordinate lies in [-2^52, 2^52] (exact as a
/// double, and a difference of two plus one fits in int64); values beyond, infinities and NaN
/// map to the ends of that range (NaN to the low end), never to undefined behaviour. Cell counts
/// of a box are products of such differences: compute them in Real (cellCount), not in int64.
struct CellCoord {
    std::int64_t x = 0, y = 0, z = 0;
    friend bool operator==(const CellCoord&, const CellCoord&) = default;
};

inline constexpr Real kMaxCellIndex = Real(4503599627370496.0);  // 2^52

inline std::int64_t cellIndex(Real value, Real inv_size) {
    const Real c = std::floor(value * inv_size);
    if (c > kMaxCellIndex) return static_cast<std::int64_t>(kMaxCellIndex);
    if (!(c >= -kMaxCellIndex)) return -static_cast<std::int64_t>(kMaxCellIndex);  // NaN too
    return static_cast<std::int64_t>(c);
}

/// Cells in the range [lo, hi] (inclusive), as a Real: up to (2^53 + 1)^3, which overflows int64.
inline Real cellCount(const CellCoord& lo, const CellCoord& hi) {
    return Real(hi.x - lo.x + 1) * Real(hi.y - lo.y + 1) * Real(hi.z - lo.z + 1);
}

inline CellCoord cellOf(const Vec3& p, Real inv_size) {
    return CellCoord{cellIndex(p.x(), inv_size), cellIndex(p.y(), inv_size),
                     cellIndex(p.z(), inv_size)};
}

/// A well-mixed 64-bit hash of a cell (and a level, for the hierarchical grid).
inline std::uint64_t hashCell(const CellCoord& c, std::uint64_t level = 0) {
    std::uint64_t h = 0x9E3779B97F4A7C15ull * (level + 1);
    for (std::int64_t v : {c.x, c.y, c.z}) {
        h ^= static_cast<std::uint64_t>(v) + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
        h *= 0xBF58476D1CE4E5B9ull;
        h ^= h >> 31;
    }
    return h;
}

/// A cell size suited to the population: twice the median of the proxies' largest AABB extents
/// (the median ignores a few huge or tiny outliers). Never zero: falls back to the mean, then 1.
inline Real medianCellSize(const ProxyTable& table) {
    std::vector<Real> extents;
    extents.reserve(static_cast<std::size_t>(table.count()));
    for (ProxyId id = 0; id < table.capacity(); ++id) {
        if (table.contains(id)) extents.push_back(table.aabb(id).extents().maxCoeff());
    }
    if (extents.empty()) return 1;
    const std::size_t mid = extents.size() / 2;
    std::nth_element(extents.begin(), extents.begin() + static_cast<std::ptrdiff_t>(mid),
                     extents.end());
    Real size = 2 * extents[mid];
    if (!(size > 0)) {
        Real sum = 0;
        for (Real e : extents) sum += e;
        size = 2 * sum / Real(extents.size());
    }
    return size > 0 ? size : Real(1);
}

/// Next power of two >= n (n >= 1).
inline std::size_t nextPowerOfTwo(std::size_t n) {
    std::size_t p = 1;
    while (p < n) p <<= 1;
    return p;
}

}  // namespace collision
