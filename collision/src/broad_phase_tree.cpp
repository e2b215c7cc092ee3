// collision/src/broad_phase_tree.cpp -- dynamic AABB tree.
// Invariants: every internal node's box contains both children's boxes; every leaf's fat box
// contains its proxy's current exact AABB; heights are 1 + max(children) and siblings differ in
// height by at most 1 after each insertion (the rotations restore it on the way up).
#include "broad_phase_tree.h"

#include <algorithm>
#include <sstream>

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

// If one child of `a` is two levels taller than the other, rotate its taller grandchild up
// (an AVL rotation; the same scheme as Box2D v2.4's b2DynamicTree::Balance). Returns the node
// now at a's place.
int DynamicAabbTree::balance(int ia) {
    Node& a = nodes_[ia];
    if (a.isLeaf() || a.height < 2) return ia;
    const int ib = a.child1;
    const int ic = a.child2;
    const int diff = nodes_[ic].height - nodes_[ib].height;
    if (diff > 1 || diff < -1) {
        // Make `up` the taller child, `keep` the other.
        const int up = diff > 1 ? ic : ib;
        Node& u = nodes_[up];
        const int f = u.child1;
        const int g = u.child2;
        // u takes a's place.
        u.child1 = ia;
        u.parent = a.parent;
        a.parent = up;
        if (u.parent == kNull) {
            root_ = up;
        } else if (nodes_[u.parent].child1 == ia) {
            nodes_[u.parent].child1 = up;
        } else {
            nodes_[u.parent].child2 = up;
        }
        // The taller grandchild stays under u; the shorter goes to a.
        const bool f_taller = nodes_[f].height > nodes_[g].height;
        const int stay = f_taller ? f : g;
        const int move = f_taller ? g : f;
        u.child2 = stay;
        if (diff > 1) {
            a.child2 = move;
        } else {
            a.child1 = move;
        }
        nodes_[move].parent = ia;
        a.box = merged(nodes_[a.child1].box, nodes_[a.child2].box);
        a.height = 1 + std::max(nodes_[a.child1].height, nodes_[a.child2].height);
        u.box = merged(nodes_[u.child1].box, nodes_[u.child2].box);
        u.height = 1 + std::max(nodes_[u.child1].height, nodes_[u.child2].height);
        return up;
    }
    return ia;
}

void DynamicAabbTree::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    counters.volumes_updated += moved_;
    moved_ = 0;
    pairs.clear();
    if (root_ == kNull) return;
    for (ProxyId a = 0; a < table_.capacity(); ++a) {
        if (!table_.contains(a)) continue;
        const Aabb& box = table_.aabb(a);
        stack_.clear();
        stack_.push_back(root_);
        while (!stack_.empty()) {
            const int index = stack_.back();
            stack_.pop_back();
            const Node& n = nodes_[index];
            ++counters.volume_tests;
            if (!n.box.overlaps(box)) continue;
            if (n.isLeaf()) {
                // The fat box overlapped; the exact boxes decide.
                if (n.proxy > a && box.overlaps(table_.aabb(n.proxy))) {
                    pairs.push_back(ProxyPair{a, n.proxy});
                }
            } else {
                stack_.push_back(n.child1);
                stack_.push_back(n.child2);
            }
        }
    }
    std::sort(pairs.begin(), pairs.end());
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void DynamicAabbTree::draw(DebugDraw& draw) const {
    if (root_ == kNull) return;
    const int root_height = std::max(1, nodes_[root_].height);
    std::vector<int> stack{root_};
    while (!stack.empty()) {
        const int index = stack.back();
        stack.pop_back();
        const Node& n = nodes_[index];
        const float t = float(n.height) / float(root_height);
        draw.drawAabb(n.box, Color{0.2f + 0.8f * t, 0.6f, 1.0f - 0.8f * t, 1});
        if (!n.isLeaf()) {
            stack.push_back(n.child1);
            stack.push_back(n.child2);
        }
    }
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
