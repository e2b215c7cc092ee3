// collision/src/broadphase/tree.cpp -- dynamic AABB tree.
// Invariants: every internal node's box contains both children's boxes; every leaf's fat box
// contains its proxy's current exact AABB; heights are 1 + max(children). Rotations on the way
// up after each insertion and removal keep the surface-area cost low (see balance).
#include "broadphase/tree.h"

#include <algorithm>
#include <sstream>
#include <utility>
#include <vector>

#include "broadphase/radix_sort.h"
#include "collision/debug_draw.h"

namespace collision {

namespace {

Aabb merged(const Aabb& a, const Aabb& b) { return Aabb{a.min.cwiseMin(b.min), a.max.cwiseMax(b.max)}; }

// Half the surface area: the cost measure of the surface-area heuristic.
Real halfArea(const Aabb& box) {
    const Vec3 e = box.extents();
    return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
}

bool containsBox(const Aabb& outer, const Aabb& inner) {
    return (outer.min.array() <= inner.min.array()).all() &&
           (inner.max.array() <= outer.max.array()).all();
}

}  // namespace

Aabb DynamicAabbTree::fatten(const Aabb& box) const {
    const Real size = box.extents().maxCoeff();
    const Real floor = Real(1e-6) * (Real(1) + box.center().cwiseAbs().maxCoeff());
    const Vec3 m = Vec3::Constant(kFatRatio * size + floor);
    return Aabb{box.min - m, box.max + m};
}

int DynamicAabbTree::allocateNode() {
    if (free_list_ == kNull) {
        nodes_.emplace_back();
        return static_cast<int>(nodes_.size()) - 1;
    }
    const int node = free_list_;
    free_list_ = nodes_[node].parent;
    nodes_[node] = Node{};
    return node;
}

void DynamicAabbTree::freeNode(int node) {
    nodes_[node].parent = free_list_;
    nodes_[node].height = -1;
    free_list_ = node;
}

void DynamicAabbTree::insert(ProxyId id, const ProxyVolumes& v) {
    table_.insert(id, v);
    if (static_cast<std::size_t>(id) >= leaf_of_.size()) leaf_of_.resize(id + 1, kNull);
    const int leaf = allocateNode();
    nodes_[leaf].box = fatten(v.aabb);
    nodes_[leaf].proxy = id;
    nodes_[leaf].height = 0;
    leaf_of_[id] = leaf;
    insertLeaf(leaf);
}

void DynamicAabbTree::remove(ProxyId id) {
    table_.remove(id);
    const int leaf = leaf_of_[id];
    removeLeaf(leaf);
    freeNode(leaf);
    leaf_of_[id] = kNull;
}

void DynamicAabbTree::move(ProxyId id, const ProxyVolumes& v) {
    table_.move(id, v);
    const int leaf = leaf_of_[id];
    if (containsBox(nodes_[leaf].box, v.aabb)) return;
    ++moved_;
    removeLeaf(leaf);
    nodes_[leaf].box = fatten(v.aabb);
    insertLeaf(leaf);
}

void DynamicAabbTree::insertLeaf(int leaf) {
    if (root_ == kNull) {
        root_ = leaf;
        nodes_[leaf].parent = kNull;
        return;
    }
    // Descend by the surface-area heuristic (Catto GDC 2019; Goldsmith & Salmon 1987): at each
    // node compare the cost of making the new leaf its sibling here with the least cost of
    // pushing it into either child (the area every ancestor would grow by is paid either way).
    const Aabb leaf_box = nodes_[leaf].box;
    int index = root_;
    while (!nodes_[index].isLeaf()) {
        const Node& n = nodes_[index];
        const Real area = halfArea(n.box);
        const Real combined = halfArea(merged(n.box, leaf_box));
        const Real cost_here = 2 * combined;
        const Real inherited = 2 * (combined - area);
        auto descendCost = [&](int child) {
            const Aabb box = merged(leaf_box, nodes_[child].box);
            const Real grow = halfArea(box) - (nodes_[child].isLeaf() ? 0 : halfArea(nodes_[child].box));
            return grow + inherited;
        };
        const Real cost1 = descendCost(n.child1);
        const Real cost2 = descendCost(n.child2);
        if (cost_here < cost1 && cost_here < cost2) break;
        index = cost1 <= cost2 ? n.child1 : n.child2;
    }

    const int sibling = index;
    const int old_parent = nodes_[sibling].parent;
    const int new_parent = allocateNode();
    nodes_[new_parent].parent = old_parent;
    nodes_[new_parent].box = merged(leaf_box, nodes_[sibling].box);
    nodes_[new_parent].height = nodes_[sibling].height + 1;
    nodes_[new_parent].child1 = sibling;
    nodes_[new_parent].child2 = leaf;
    nodes_[sibling].parent = new_parent;
    nodes_[leaf].parent = new_parent;
    if (old_parent == kNull) {
        root_ = new_parent;
    } else if (nodes_[old_parent].child1 == sibling) {
        nodes_[old_parent].child1 = new_parent;
    } else {
        nodes_[old_parent].child2 = new_parent;
    }

    // Walk back up: rebalance, refit boxes and heights.
    for (index = nodes_[leaf].parent; index != kNull; index = nodes_[index].parent) {
        index = balance(index);
        Node& n = nodes_[index];
        n.height = 1 + std::max(nodes_[n.child1].height, nodes_[n.child2].height);
        n.box = merged(nodes_[n.child1].box, nodes_[n.child2].box);
    }
}

void DynamicAabbTree::removeLeaf(int leaf) {
    if (leaf == root_) {
        root_ = kNull;
        return;
    }
    const int parent = nodes_[leaf].parent;
    const int grand = nodes_[parent].parent;
    const int sibling = nodes_[parent].child1 == leaf ? nodes_[parent].child2 : nodes_[parent].child1;
    if (grand == kNull) {
        root_ = sibling;
        nodes_[sibling].parent = kNull;
        freeNode(parent);
        return;
    }
    if (nodes_[grand].child1 == parent) {
        nodes_[grand].child1 = sibling;
    } else {
        nodes_[grand].child2 = sibling;
    }
    nodes_[sibling].parent = grand;
    freeNode(parent);
    for (int index = grand; index != kNull; index = nodes_[index].parent) {
        index = balance(index);
        Node& n = nodes_[index];
        n.height = 1 + std::max(nodes_[n.child1].height, nodes_[n.child2].height);
        n.box = merged(nodes_[n.child1].box, nodes_[n.child2].box);
    }
}

// Tree rotations by the surface-area heuristic (Catto GDC 2019; Box2D v3's b2RotateNodes;
// Kopta et al. 2012): at node A with children B and C, swap B with a grandchild under C, or C
// with a grandchild under B, when that shrinks the area of the child that changes. A's own box
// is unchanged by any of the four swaps, so only one child box and the heights are refitted.
// Unlike height (AVL) balancing, which ignores the boxes and made pair searches test ~70 volume
// pairs per reported pair, this keeps siblings spatially close. Returns `ia` (A keeps its place).
int DynamicAabbTree::balance(int ia) {
    Node& a = nodes_[ia];
    if (a.isLeaf() || a.height < 2) return ia;
    const int ib = a.child1;
    const int ic = a.child2;
    Node& b = nodes_[ib];
    Node& c = nodes_[ic];
    enum class Swap { None, BF, BG, CD, CE };
    Swap best = Swap::None;
    Real best_gain = 0;
    if (!c.isLeaf()) {
        const Real area_c = halfArea(c.box);
        const Real bf = area_c - halfArea(merged(b.box, nodes_[c.child2].box));  // B <-> F
        const Real bg = area_c - halfArea(merged(b.box, nodes_[c.child1].box));  // B <-> G
        if (bf > best_gain) { best = Swap::BF; best_gain = bf; }
        if (bg > best_gain) { best = Swap::BG; best_gain = bg; }
    }
    if (!b.isLeaf()) {
        const Real area_b = halfArea(b.box);
        const Real cd = area_b - halfArea(merged(c.box, nodes_[b.child2].box));  // C <-> D
        const Real ce = area_b - halfArea(merged(c.box, nodes_[b.child1].box));  // C <-> E
        if (cd > best_gain) { best = Swap::CD; best_gain = cd; }
        if (ce > best_gain) { best = Swap::CE; best_gain = ce; }
    }
    // Swap A's child `outer` with `inner`, a child of A's other child `mid`.
    auto swapInto = [&](int outer, int mid, bool first_of_mid, bool outer_is_child1) {
        Node& m = nodes_[mid];
        const int inner = first_of_mid ? m.child1 : m.child2;
        (first_of_mid ? m.child1 : m.child2) = outer;
        nodes_[outer].parent = mid;
        (outer_is_child1 ? a.child1 : a.child2) = inner;
        nodes_[inner].parent = ia;
        m.box = merged(nodes_[m.child1].box, nodes_[m.child2].box);
        m.height = 1 + std::max(nodes_[m.child1].height, nodes_[m.child2].height);
    };
    switch (best) {
        case Swap::None: return ia;
        case Swap::BF: swapInto(ib, ic, true, true); break;
        case Swap::BG: swapInto(ib, ic, false, true); break;
        case Swap::CD: swapInto(ic, ib, true, false); break;
        case Swap::CE: swapInto(ic, ib, false, false); break;
    }
    a.height = 1 + std::max(nodes_[a.child1].height, nodes_[a.child2].height);
    return ia;
}

void DynamicAabbTree::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    counters.volumes_updated += moved_;
    moved_ = 0;
    pairs.clear();
    if (root_ == kNull) return;
    // One self-traversal of the tree (tandem descent of the tree against itself): a pair
    // (n, n) stands for the pairs inside subtree n, and expands into its two children's own
    // pairs and the pair of children; a pair of distinct nodes whose boxes overlap descends the
    // taller node. Every unordered pair of leaves is reached exactly once, through the node
    // where their paths split, and a subtree pair is dropped as soon as its boxes are apart
    // (Catto GDC 2019; the self-collision traversal of RTCD 6.3.2). Leaves meet on their fat
    // boxes; the exact AABBs decide.
    const int shift = radix::bitsFor(static_cast<std::uint64_t>(table_.capacity()));
    keys_.clear();
    std::int64_t tests = 0;
    pair_stack_.clear();
    pair_stack_.push_back({root_, root_});
    while (!pair_stack_.empty()) {
        const auto [ia, ib] = pair_stack_.back();
        pair_stack_.pop_back();
        const Node& a = nodes_[ia];
        if (ia == ib) {
            if (a.isLeaf()) continue;
            pair_stack_.push_back({a.child1, a.child1});
            pair_stack_.push_back({a.child2, a.child2});
            pair_stack_.push_back({a.child1, a.child2});
            continue;
        }
        const Node& b = nodes_[ib];
        ++tests;
        if (!a.box.overlaps(b.box)) continue;
        if (a.isLeaf() && b.isLeaf()) {
            ++tests;
            if (table_.aabb(a.proxy).overlaps(table_.aabb(b.proxy))) {
                const ProxyId lo = std::min(a.proxy, b.proxy);
                const ProxyId hi = std::max(a.proxy, b.proxy);
                keys_.push_back((std::uint64_t(lo) << shift) | std::uint64_t(hi));
            }
        } else if (b.isLeaf() || (!a.isLeaf() && a.height >= b.height)) {
            pair_stack_.push_back({a.child1, ib});
            pair_stack_.push_back({a.child2, ib});
        } else {
            pair_stack_.push_back({ia, b.child1});
            pair_stack_.push_back({ia, b.child2});
        }
    }
    counters.volume_tests += tests;
    radix::keysToSortedPairs(keys_, scratch_, shift, pairs);
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void DynamicAabbTree::draw(DebugDraw& draw, const Aabb& /*bounds*/) const {
    // Every node's fat box, one colour per depth (root 0).
    if (root_ == kNull) return;
    int depths = 0;
    std::vector<std::pair<int, int>> stack{{root_, 0}};  // (node, depth)
    while (!stack.empty()) {
        const auto [index, depth] = stack.back();
        stack.pop_back();
        const Node& n = nodes_[index];
        draw.drawAabb(n.box, structureColor(depth));
        depths = std::max(depths, depth + 1);
        if (!n.isLeaf()) {
            stack.push_back({n.child1, depth + 1});
            stack.push_back({n.child2, depth + 1});
        }
    }
    legendByNumber(draw, "tree nodes (fat boxes), depth", depths, " (root 0)");
}

std::string DynamicAabbTree::validateNode(int node, int parent) const {
    const Node& n = nodes_[node];
    std::ostringstream out;
    if (n.parent != parent) out << "node " << node << " has a wrong parent; ";
    if (n.isLeaf()) {
        if (n.height != 0) out << "leaf " << node << " height " << n.height << "; ";
        if (!table_.contains(n.proxy)) {
            out << "leaf " << node << " holds an absent proxy; ";
        } else if (!containsBox(n.box, table_.aabb(n.proxy))) {
            out << "leaf " << node << " fat box misses its AABB; ";
        }
        return out.str();
    }
    const Node& c1 = nodes_[n.child1];
    const Node& c2 = nodes_[n.child2];
    if (n.height != 1 + std::max(c1.height, c2.height)) out << "node " << node << " height; ";
    if (!containsBox(n.box, c1.box) || !containsBox(n.box, c2.box)) {
        out << "node " << node << " box misses a child; ";
    }
    out << validateNode(n.child1, node) << validateNode(n.child2, node);
    return out.str();
}

std::string DynamicAabbTree::validate() const {
    if (root_ == kNull) return table_.count() == 0 ? "" : "empty tree with proxies";
    return validateNode(root_, kNull);
}

}  // namespace collision
