// collision/src/bvh/typed.h -- calling a function template with the typed trees behind MeshBvh
// handles (treeOf over every type of BvhVolumeTypes; the wide tree, kWideObbName, as the binary
// OBB tree it was collapsed from): how the free functions on hierarchies (replay, levels) reach
// Bvh<BV> without a virtual per operation. Private to collision.
#pragma once

#include <tuple>
#include <utility>

#include "collision/assert.h"
#include "collision/bvh/bvh.h"

namespace collision {

namespace typed_detail {

// out = f(tree as Bvh<BV>) when `tree` holds BV.
template <class BV, class R, class F>
bool tryTree(const MeshBvh& tree, R& out, F& f) {
    const Bvh<BV>* typed = treeOf<BV>(tree);
    if (typed == nullptr) return false;
    out = f(*typed);
    return true;
}

template <class R, class F, class... BV>
R withTreeOf(const MeshBvh& tree, R fallback, F& f, std::tuple<BV...>* /*types*/) {
    R out = std::move(fallback);
    (tryTree<BV>(tree, out, f) || ...);
    return out;
}

}  // namespace typed_detail

/// f(tree) with `tree`'s typed Bvh<BV> (the wide tree's binary Bvh<Obb>, obbTreeOf);
/// `fallback` for a handle of no known type.
template <class R, class F>
R withTree(const MeshBvh& tree, R fallback, F&& f) {
    if (tree.volumeName() == kWideObbName) {
        const Bvh<Obb>* binary = obbTreeOf(tree);
        return binary != nullptr ? f(*binary) : std::move(fallback);
    }
    return typed_detail::withTreeOf(tree, std::move(fallback), f,
                                    static_cast<BvhVolumeTypes*>(nullptr));
}

/// The typed tree of `b` when it holds the same volume type as `like`, else null.
template <class BV>
const Bvh<BV>* sameTypeTree(const Bvh<BV>& /*like*/, const MeshBvh& b) {
    return treeOf<BV>(b);
}

/// The binary OBB tree of `b`, an obb tree or a wide one like `like`'s owner.
inline const Bvh<Obb>* sameTypeTree(const Bvh<Obb>& /*like*/, const MeshBvh& b) {
    return obbTreeOf(b);
}

/// f(a, b) with the typed trees of `a` and `b`, which must hold the same volume type (asserted;
/// `fallback` if not).
template <class R, class F>
R withTreePair(const MeshBvh& a, const MeshBvh& b, R fallback, F&& f) {
    CDLAB_ASSERT(a.sameVolumeType(b), "BVH query between different volume types");
    if (!a.sameVolumeType(b)) return fallback;
    return withTree(a, std::move(fallback),
                    [&](const auto& tree_a) { return f(tree_a, *sameTypeTree(tree_a, b)); });
}

}  // namespace collision
