// collision/src/bvh/wide.cpp -- the 4-wide OBB tree: collapse of the binary tree, the four-lane
// box test, and the tandem traversal over wide nodes.
// Invariant: every lane is a bit-exact copy of a binary node's box, each binary node reachable
// from the root appears in exactly one lane, and unused lanes repeat lane 0 (masked off), so the
// wide queries test the same boxes as the binary ones, with the same slack, and the same
// triangles (bit-identical corners, moved by the query's one BvhTransform).
#include "bvh/wide.h"

#include <algorithm>
#include <cstring>
#include <sstream>
#include <string>
#include <utility>

#include "bvh/traversal.h"
#include "collision/assert.h"

namespace collision {

namespace {

WideLanes absLanes(WideLanes v) {
    const WideMask magnitude = {0x7fffffffffffffff, 0x7fffffffffffffff};
    return reinterpret_cast<WideLanes>(reinterpret_cast<WideMask>(v) & magnitude);
}

WideMask greater(WideLanes a, WideLanes b) { return reinterpret_cast<WideMask>(a > b); }

WideLanes load(const double (&lanes)[4], int half) {
    WideLanes v;
    std::memcpy(&v, &lanes[2 * half], sizeof v);
    return v;
}

// Lanes 2 h and 2 h + 1 of `n` against box `b`: bit 0/1 set for an overlapping lane. The
// fifteen axes of testSat15 in its order; |R| + 16 eps enters as |R| plus 16 eps times the sum
// of the half extents it multiplies (the same bound, fewer live registers).
unsigned overlapHalf(const WideObbNode& n, int h, const Obb& b, Real tol) {
    const Real e = Real(16) * kEpsilon;
    const Vec3& hb = b.half_extents;
    const WideLanes ha[3] = {load(n.half[0], h), load(n.half[1], h), load(n.half[2], h)};
    WideLanes d[3];
    for (int r = 0; r < 3; ++r) d[r] = b.center[r] - load(n.center[r], h);
    WideLanes t[3];
    WideLanes rot[3][3];
    for (int i = 0; i < 3; ++i) {
        const WideLanes a0 = load(n.axes[3 * i], h);
        const WideLanes a1 = load(n.axes[3 * i + 1], h);
        const WideLanes a2 = load(n.axes[3 * i + 2], h);
        t[i] = a0 * d[0] + a1 * d[1] + a2 * d[2];
        for (int j = 0; j < 3; ++j) {
            rot[i][j] = a0 * b.axes(0, j) + a1 * b.axes(1, j) + a2 * b.axes(2, j);
        }
    }
    const Real face_a_slack = tol + e * (hb[0] + hb[1] + hb[2]);
    WideMask sep = {0, 0};
    for (int i = 0; i < 3; ++i) {
        sep |= greater(absLanes(t[i]), ha[i] + absLanes(rot[i][0]) * hb[0] +
                                           absLanes(rot[i][1]) * hb[1] +
                                           absLanes(rot[i][2]) * hb[2] + face_a_slack);
    }
    const WideLanes face_b_slack = tol + e * (ha[0] + ha[1] + ha[2]);
    for (int j = 0; j < 3; ++j) {
        sep |= greater(absLanes(t[0] * rot[0][j] + t[1] * rot[1][j] + t[2] * rot[2][j]),
                       absLanes(rot[0][j]) * ha[0] + absLanes(rot[1][j]) * ha[1] +
                           absLanes(rot[2][j]) * ha[2] + hb[j] + face_b_slack);
    }
    if ((sep[0] & sep[1]) != 0) return 0;
    for (int i = 0; i < 3; ++i) {
        const int i1 = (i + 1) % 3;
        const int i2 = (i + 2) % 3;
        for (int j = 0; j < 3; ++j) {
            const int j1 = (j + 1) % 3;
            const int j2 = (j + 2) % 3;
            const WideLanes ra = ha[i1] * absLanes(rot[i2][j]) + ha[i2] * absLanes(rot[i1][j]) +
                                 e * (ha[i1] + ha[i2]);
            const WideLanes rb = hb[j1] * absLanes(rot[i][j2]) + hb[j2] * absLanes(rot[i][j1]) +
                                 e * (hb[j1] + hb[j2]);
            const WideLanes dist = absLanes(t[i2] * rot[i1][j] - t[i1] * rot[i2][j]);
            sep |= greater(dist, ra + rb + tol);
        }
    }
    return (sep[0] == 0 ? 1u : 0u) | (sep[1] == 0 ? 2u : 0u);
}

// Lane `l` of `node` as a box.
Obb laneBox(const WideObbNode& node, int l) {
    Obb box;
    for (int r = 0; r < 3; ++r) {
        box.center[r] = node.center[r][l];
        box.half_extents[r] = node.half[r][l];
        for (int c = 0; c < 3; ++c) box.axes(r, c) = node.axes[3 * c + r][l];
    }
    return box;
}

}  // namespace

unsigned overlapLanes(const WideObbNode& n, const Obb& b, Real tol) {
    unsigned hits = overlapHalf(n, 0, b, tol);
    if (n.size > 2) hits |= overlapHalf(n, 1, b, tol) << 2;
    return hits & ((1u << n.size) - 1);
}

WideObbTree::WideObbTree(const TriangleMesh& mesh, const BvhBuildOptions& options)
    : binary_(mesh, options) {
    collapse();
}

void WideObbTree::fillLane(WideObbNode& node, int lane, std::int32_t binary_index) const {
    const auto& src = binary_.nodes()[static_cast<std::size_t>(binary_index)];
    for (int r = 0; r < 3; ++r) {
        node.center[r][lane] = src.volume.center[r];
        node.half[r][lane] = src.volume.half_extents[r];
        for (int c = 0; c < 3; ++c) node.axes[3 * c + r][lane] = src.volume.axes(r, c);
    }
    node.cost[static_cast<std::size_t>(lane)] = src.cost;
    node.first[static_cast<std::size_t>(lane)] = src.first;
    node.count[static_cast<std::size_t>(lane)] = src.count;
}

void WideObbTree::collapse() {
    nodes_.clear();
    lane_source_.clear();
    if (binary_.nodes().empty()) return;
    // At most one wide node per internal binary node, plus the root's.
    const std::size_t bound = binary_.nodes().size() / 2 + 2;
    nodes_.reserve(bound);
    lane_source_.reserve(4 * bound);
    nodes_.emplace_back();
    lane_source_.assign(4, 0);
    WideObbNode& root = nodes_[0];
    root.size = 1;
    for (int l = 0; l < 4; ++l) fillLane(root, l, 0);
    if (!binary_.nodes()[0].isLeaf()) nodes_[0].child[0] = collapseNode(0);
}

// The wide node of binary internal node `n`'s children, the largest internal one split until
// there are four (Dammertz et al. 2008 collapse their binary trees this way).
std::int32_t WideObbTree::collapseNode(std::int32_t n) {
    const auto& bin = binary_.nodes();
    auto at = [&](std::int32_t i) -> const Bvh<Obb>::Node& {
        return bin[static_cast<std::size_t>(i)];
    };
    std::array<std::int32_t, 4> kids{n + 1, at(n).right, -1, -1};
    int size = 2;
    while (size < 4) {
        int split = -1;
        for (int k = 0; k < size; ++k) {
            const auto& node = at(kids[static_cast<std::size_t>(k)]);
            if (!node.isLeaf() &&
                (split < 0 || node.cost > at(kids[static_cast<std::size_t>(split)]).cost)) {
                split = k;
            }
        }
        if (split < 0) break;
        const std::int32_t parent = kids[static_cast<std::size_t>(split)];
        for (int k = size; k > split + 1; --k) {
            kids[static_cast<std::size_t>(k)] = kids[static_cast<std::size_t>(k - 1)];
        }
        kids[static_cast<std::size_t>(split)] = parent + 1;
        kids[static_cast<std::size_t>(split + 1)] = at(parent).right;
        ++size;
    }
    const auto index = static_cast<std::int32_t>(nodes_.size());
    nodes_.emplace_back();
    lane_source_.insert(lane_source_.end(), 4, -1);
    for (int l = 0; l < 4; ++l) {
        const int k = l < size ? l : 0;  // unused lanes repeat lane 0
        fillLane(nodes_[static_cast<std::size_t>(index)], l, kids[static_cast<std::size_t>(k)]);
    }
    nodes_[static_cast<std::size_t>(index)].size = size;
    for (int l = 0; l < size; ++l) {
        const std::int32_t kid = kids[static_cast<std::size_t>(l)];
        lane_source_[static_cast<std::size_t>(4 * index + l)] = kid;
        if (!at(kid).isLeaf()) {
            const std::int32_t child = collapseNode(kid);
            nodes_[static_cast<std::size_t>(index)].child[static_cast<std::size_t>(l)] = child;
        }
    }
    return index;
}

bool WideObbTree::validate(std::string* error) const {
    if (!binary_.validate(error)) return false;
    auto fail = [&](const std::string& what) {
        if (error) *error = what;
        return false;
    };
    const auto& bin = binary_.nodes();
    std::vector<int> seen(bin.size(), 0);
    for (std::size_t w = 0; w < nodes_.size(); ++w) {
        const WideObbNode& node = nodes_[w];
        for (int l = 0; l < node.size; ++l) {
            const std::int32_t src = lane_source_[4 * w + static_cast<std::size_t>(l)];
            if (src < 0 || static_cast<std::size_t>(src) >= bin.size()) {
                return fail("wide node " + std::to_string(w) + " lane " + std::to_string(l) +
                            ": no binary node");
            }
            ++seen[static_cast<std::size_t>(src)];
            const auto& b = bin[static_cast<std::size_t>(src)];
            const Obb box = laneBox(node, l);
            const auto lane = static_cast<std::size_t>(l);
            if (box.center != b.volume.center || box.axes != b.volume.axes ||
                box.half_extents != b.volume.half_extents || node.cost[lane] != b.cost ||
                node.count[lane] != b.count || (b.isLeaf() && node.first[lane] != b.first) ||
                (b.isLeaf() != (node.child[lane] < 0))) {
                std::ostringstream out;
                out << "wide node " << w << " lane " << l << " differs from binary node " << src;
                return fail(out.str());
            }
        }
    }
    for (std::size_t i = 0; i < seen.size(); ++i) {
        // Every binary node is in one lane except those split by the collapse (not leaves).
        if (seen[i] > 1 || (bin[i].isLeaf() && seen[i] != 1)) {
            return fail("binary node " + std::to_string(i) + " in " + std::to_string(seen[i]) +
                        " lanes");
        }
    }
    return true;
}

std::int32_t WideObbTree::refit(const TriangleMesh& mesh) {
    const std::int32_t updated = binary_.refit(mesh);
    for (std::size_t w = 0; w < nodes_.size(); ++w) {
        for (int l = 0; l < 4; ++l) {
            const std::int32_t src =
                lane_source_[4 * w + static_cast<std::size_t>(l < nodes_[w].size ? l : 0)];
            fillLane(nodes_[w], l, src);
        }
    }
    return updated;
}

namespace {

// The tandem traversal over wide nodes (Gottschalk 1996 §5 with the descent of traverse()): a
// stack entry is a pair of lanes (node * 4 + lane) whose boxes overlap; pop one, and at two
// leaves test their triangles, else open the child node of the larger box and test its lanes
// against the other box in one pass, pushing the pairs that overlap. A's boxes are tested in A's
// frame (B's box moved by x), B's in B's frame (A's moved by the inverse), each moved once per
// run of pops that keeps it.
template <class OnPair>
bool traverseWide(const WideObbTree& ta, const WideObbTree& tb, const BvhTransform& x,
                  BvhQueryStats* stats, OnPair&& on_pair) {
    const auto& na = ta.nodes();
    const auto& nb = tb.nodes();
    if (na.empty() || nb.empty()) return false;
    const Bvh<Obb>& a = ta.binary();
    const Bvh<Obb>& b = tb.binary();
    std::int64_t bv_tests = 1;
    std::int64_t tri_tests = 0;
    bool stopped = false;
    if (BvTraits<Obb>::overlaps(laneBox(na[0], 0), laneBox(nb[0], 0), x)) {
        // Each pop pushes at most four pairs, each one level deeper in A or B.
        NodeStack<std::pair<std::int32_t, std::int32_t>> stack(
            static_cast<std::size_t>(3 * (ta.depth() + tb.depth()) + 4));
        stack.push({0, 0});
        const Mat3 rt = x.r.transpose();
        Obb moved_b;
        Obb moved_a;
        std::int32_t moved_b_ref = -1;
        std::int32_t moved_a_ref = -1;
        while (!stack.empty() && !stopped) {
            const auto [ra, rb] = stack.pop();
            const WideObbNode& wa = na[static_cast<std::size_t>(ra >> 2)];
            const WideObbNode& wb = nb[static_cast<std::size_t>(rb >> 2)];
            const auto la = static_cast<std::size_t>(ra & 3);
            const auto lb = static_cast<std::size_t>(rb & 3);
            const bool leaf_a = wa.count[la] > 0;
            const bool leaf_b = wb.count[lb] > 0;
            if (leaf_a && leaf_b) {
                const std::int32_t end_b = wb.first[lb] + wb.count[lb];
                for (std::int32_t j = wb.first[lb]; j < end_b && !stopped; ++j) {
                    const auto& tri_b = b.leafTriangle(j);
                    const std::array<Vec3, 3> moved{x.apply(tri_b[0]), x.apply(tri_b[1]),
                                                    x.apply(tri_b[2])};
                    for (std::int32_t i = wa.first[la]; i < wa.first[la] + wa.count[la]; ++i) {
                        const auto& tri_a = a.leafTriangle(i);
                        ++tri_tests;
                        if (!testTriangleTriangle(tri_a[0], tri_a[1], tri_a[2], moved[0], moved[1],
                                                  moved[2])) {
                            continue;
                        }
                        if (on_pair(i, j, tri_a, moved)) {
                            stopped = true;
                            break;
                        }
                    }
                }
                continue;
            }
            if (leaf_b || (!leaf_a && wa.cost[la] >= wb.cost[lb])) {
                if (rb != moved_b_ref) {
                    moved_b = BvTraits<Obb>::move(laneBox(wb, static_cast<int>(lb)), x);
                    moved_b_ref = rb;
                }
                const std::int32_t c = wa.child[la];
                const WideObbNode& node = na[static_cast<std::size_t>(c)];
                const unsigned hits = overlapLanes(node, moved_b, x.tol);
                bv_tests += node.size;
                for (int l = node.size - 1; l >= 0; --l) {
                    if ((hits >> l) & 1u) stack.push({4 * c + l, rb});
                }
            } else {
                if (ra != moved_a_ref) {
                    const Obb box = laneBox(wa, static_cast<int>(la));
                    moved_a = Obb{rt * (box.center - x.t), rt * box.axes, box.half_extents};
                    moved_a_ref = ra;
                }
                const std::int32_t c = wb.child[lb];
                const WideObbNode& node = nb[static_cast<std::size_t>(c)];
                const unsigned hits = overlapLanes(node, moved_a, x.tol);
                bv_tests += node.size;
                for (int l = node.size - 1; l >= 0; --l) {
                    if ((hits >> l) & 1u) stack.push({ra, 4 * c + l});
                }
            }
        }
    }
    if (stats) {
        stats->bv_tests += bv_tests;
        stats->triangle_tests += tri_tests;
    }
    return stopped;
}

}  // namespace

bool testWide(const WideObbTree& a, const WideObbTree& b, const BvhTransform& x,
              BvhQueryStats* stats) {
    return traverseWide(a, b, x, stats,
                        [](std::int32_t, std::int32_t, const std::array<Vec3, 3>&,
                           const std::array<Vec3, 3>&) { return true; });
}

std::vector<TrianglePair> intersectWide(const WideObbTree& a, const WideObbTree& b,
                                        const BvhTransform& x, BvhQueryStats* stats) {
    std::vector<TrianglePair> pairs;
    traverseWide(a, b, x, stats,
                 [&](std::int32_t i, std::int32_t j, const std::array<Vec3, 3>&,
                     const std::array<Vec3, 3>&) {
                     pairs.push_back({a.binary().leafTriangleId(i), b.binary().leafTriangleId(j)});
                     return false;
                 });
    std::sort(pairs.begin(), pairs.end());  // each triangle is in one leaf: unique
    return pairs;
}

bool visitWide(const WideObbTree& a, const WideObbTree& b, const BvhTransform& x,
               TrianglePairVisitor& visitor, BvhQueryStats* stats) {
    return traverseWide(a, b, x, stats,
                        [&](std::int32_t i, std::int32_t j, const std::array<Vec3, 3>& tri_a,
                            const std::array<Vec3, 3>& moved) {
                            return visitor.visit(a.binary().leafTriangleId(i), tri_a,
                                                 b.binary().leafTriangleId(j), moved);
                        });
}

}  // namespace collision
