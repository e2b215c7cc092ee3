// collision/src/narrowphase/pair_table.h -- the [ShapeType][ShapeType] dispatch tables of
// collide() and contact(): one entry per ordered pair of shape types. Private to collision.
#pragma once

#include <array>
#include <cstddef>

#include "collision/geometry/shape.h"

namespace collision {

template <class Entry>
using PairTable = std::array<std::array<Entry, kShapeTypeCount>, kShapeTypeCount>;

/// The table with every entry `all`.
template <class Entry>
constexpr PairTable<Entry> filledPairTable(Entry all) {
    PairTable<Entry> table{};
    for (auto& row : table) row.fill(all);
    return table;
}

template <class Entry>
constexpr Entry& pairEntry(PairTable<Entry>& table, ShapeType first, ShapeType second) {
    return table[static_cast<std::size_t>(first)][static_cast<std::size_t>(second)];
}

template <class Entry>
constexpr const Entry& pairEntry(const PairTable<Entry>& table, ShapeType first,
                                 ShapeType second) {
    return table[static_cast<std::size_t>(first)][static_cast<std::size_t>(second)];
}

}  // namespace collision
