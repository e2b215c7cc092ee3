// collision/src/bvh/mesh_bvh.cpp -- MeshBvh, a Bvh<BV> of a volume type chosen at run time: the
// queries of bvh.h behind one interface, the typed tree for the code that needs it (treeOf), and
// the lookup of a volume type by name.
#include <algorithm>
#include <limits>
#include <memory>
#include <tuple>
#include <type_traits>

#include "bvh/traversal.h"
#include "bvh/wide.h"
#include "collision/assert.h"
#include "collision/bvh/bvh.h"
#include "volumes/bvh_volumes.h"

namespace collision {

namespace {

template <class BV>
class MeshBvhOf final : public MeshBvh {
public:
    MeshBvhOf(const TriangleMesh& mesh, const BvhBuildOptions& options) : tree_(mesh, options) {}
    const Bvh<BV>& tree() const { return tree_; }
    std::unique_ptr<MeshBvh> clone() const override { return std::make_unique<MeshBvhOf>(*this); }
    std::string_view volumeName() const override { return BvName<BV>::value; }
    std::int32_t nodeCount() const override {
        return static_cast<std::int32_t>(tree_.nodes().size());
    }
    int depth() const override { return tree_.depth(); }
    bool validate(std::string* error) const override { return tree_.validate(error); }
    bool testOverlap(const MeshBvh& b, const Pose& b_in_a, BvhQueryStats* stats) const override {
        const auto* other = dynamic_cast<const MeshBvhOf<BV>*>(&b);
        CDLAB_ASSERT(other != nullptr, "BVH query between different volume types");
        return other != nullptr && testBvhBvh(tree_, other->tree_, b_in_a, stats);
    }
    std::vector<TrianglePair> intersect(const MeshBvh& b, const Pose& b_in_a,
                                        BvhQueryStats* stats) const override {
        const auto* other = dynamic_cast<const MeshBvhOf<BV>*>(&b);
        CDLAB_ASSERT(other != nullptr, "BVH query between different volume types");
        if (other == nullptr) return {};
        return intersectBvhBvh(tree_, other->tree_, b_in_a, stats);
    }
    std::int32_t triangleCount() const override { return tree_.triangleCount(); }
    std::int32_t refit(const TriangleMesh& mesh) override { return tree_.refit(mesh); }
    MeshDistance distance(const MeshBvh& b, const Pose& b_in_a,
                          BvhQueryStats* stats) const override {
        const auto* other = dynamic_cast<const MeshBvhOf<BV>*>(&b);
        CDLAB_ASSERT(other != nullptr, "BVH query between different volume types");
        if (other == nullptr) {
            MeshDistance none;
            none.distance = std::numeric_limits<Real>::infinity();
            return none;
        }
        return distanceBvhBvh(tree_, other->tree_, b_in_a, stats);
    }
    std::vector<TrianglePair> intersectSelf(BvhQueryStats* stats) const override {
        return collision::intersectSelf(tree_, stats);
    }
    bool sameVolumeType(const MeshBvh& b) const override {
        return dynamic_cast<const MeshBvhOf<BV>*>(&b) != nullptr;
    }
    bool visitIntersecting(const MeshBvh& b, const Mat3& rotation, const Vec3& translation,
                           TrianglePairVisitor& visitor, BvhQueryStats* stats) const override {
        const auto* other = dynamic_cast<const MeshBvhOf<BV>*>(&b);
        CDLAB_ASSERT(other != nullptr, "BVH query between different volume types");
        if (other == nullptr) return false;
        const Bvh<BV>& tb = other->tree_;
        const BvhTransform x = makeBvhTransform(rotation, translation, tree_.scale(), tb.scale());
        return traverse(tree_, tb, x, stats,
                        [&](std::int32_t i, std::int32_t j, const std::array<Vec3, 3>& ta,
                            const std::array<Vec3, 3>& moved) {
                            return visitor.visit(tree_.leafTriangleId(i), ta, tb.leafTriangleId(j),
                                                 moved);
                        });
    }
    bool visitNearBox(const Vec3& box_min, const Vec3& box_max, const Mat3& rotation,
                      const Vec3& translation, TriangleVisitor& visitor,
                      BvhQueryStats* stats) const override {
        if (tree_.nodes().empty()) return false;
        const Real box_scale =
            (box_max - box_min).maxCoeff() +
            std::max(box_min.cwiseAbs().maxCoeff(), box_max.cwiseAbs().maxCoeff());
        const BV volume = BvTraits<BV>::fit(boxSurfaceCorners(box_min, box_max));
        const BvhTransform x = makeBvhTransform(rotation, translation, tree_.scale(), box_scale);
        return traverseVolume(tree_, volume, x, stats,
                              [&](std::int32_t i, const std::array<Vec3, 3>& corners) {
                                  return visitor.visit(tree_.leafTriangleId(i), corners);
                              });
    }

private:
    Bvh<BV> tree_;
};

// The 4-wide OBB tree (wide.h): the tandem queries run on the wide nodes, the others on the
// binary tree it was collapsed from (same triangles, same boxes).
class MeshBvhWide final : public MeshBvh {
public:
    MeshBvhWide(const TriangleMesh& mesh, const BvhBuildOptions& options) : tree_(mesh, options) {}
    const WideObbTree& tree() const { return tree_; }
    std::unique_ptr<MeshBvh> clone() const override { return std::make_unique<MeshBvhWide>(*this); }
    std::string_view volumeName() const override { return kWideObbName; }
    std::int32_t nodeCount() const override {
        return static_cast<std::int32_t>(tree_.nodes().size());
    }
    int depth() const override { return tree_.depth(); }
    bool validate(std::string* error) const override { return tree_.validate(error); }
    bool testOverlap(const MeshBvh& b, const Pose& b_in_a, BvhQueryStats* stats) const override {
        const WideObbTree* other = otherTree(b);
        return other != nullptr &&
               testWide(tree_, *other, makeBvhTransform(b_in_a, scale(), other->binary().scale()),
                        stats);
    }
    std::vector<TrianglePair> intersect(const MeshBvh& b, const Pose& b_in_a,
                                        BvhQueryStats* stats) const override {
        const WideObbTree* other = otherTree(b);
        if (other == nullptr) return {};
        return intersectWide(tree_, *other,
                             makeBvhTransform(b_in_a, scale(), other->binary().scale()), stats);
    }
    std::int32_t triangleCount() const override { return tree_.binary().triangleCount(); }
    std::int32_t refit(const TriangleMesh& mesh) override { return tree_.refit(mesh); }
    MeshDistance distance(const MeshBvh& b, const Pose& b_in_a,
                          BvhQueryStats* stats) const override {
        const WideObbTree* other = otherTree(b);
        if (other == nullptr) {
            MeshDistance none;
            none.distance = std::numeric_limits<Real>::infinity();
            return none;
        }
        return distanceBvhBvh(tree_.binary(), other->binary(), b_in_a, stats);
    }
    std::vector<TrianglePair> intersectSelf(BvhQueryStats* stats) const override {
        return collision::intersectSelf(tree_.binary(), stats);
    }
    bool sameVolumeType(const MeshBvh& b) const override {
        return dynamic_cast<const MeshBvhWide*>(&b) != nullptr;
    }
    bool visitIntersecting(const MeshBvh& b, const Mat3& rotation, const Vec3& translation,
                           TrianglePairVisitor& visitor, BvhQueryStats* stats) const override {
        const WideObbTree* other = otherTree(b);
        if (other == nullptr) return false;
        const BvhTransform x =
            makeBvhTransform(rotation, translation, scale(), other->binary().scale());
        return visitWide(tree_, *other, x, visitor, stats);
    }
    bool visitNearBox(const Vec3& box_min, const Vec3& box_max, const Mat3& rotation,
                      const Vec3& translation, TriangleVisitor& visitor,
                      BvhQueryStats* stats) const override {
        const Bvh<Obb>& tree = tree_.binary();
        if (tree.nodes().empty()) return false;
        const Real box_scale =
            (box_max - box_min).maxCoeff() +
            std::max(box_min.cwiseAbs().maxCoeff(), box_max.cwiseAbs().maxCoeff());
        const Obb volume = BvTraits<Obb>::fit(boxSurfaceCorners(box_min, box_max));
        const BvhTransform x = makeBvhTransform(rotation, translation, tree.scale(), box_scale);
        return traverseVolume(tree, volume, x, stats,
                              [&](std::int32_t i, const std::array<Vec3, 3>& corners) {
                                  return visitor.visit(tree.leafTriangleId(i), corners);
                              });
    }

private:
    Real scale() const { return tree_.binary().scale(); }
    const WideObbTree* otherTree(const MeshBvh& b) const {
        const auto* other = dynamic_cast<const MeshBvhWide*>(&b);
        CDLAB_ASSERT(other != nullptr, "BVH query between different volume types");
        return other != nullptr ? &other->tree_ : nullptr;
    }

    WideObbTree tree_;
};

}  // namespace

template <class BV>
const Bvh<BV>* treeOf(const MeshBvh& tree) {
    const auto* typed = dynamic_cast<const MeshBvhOf<BV>*>(&tree);
    return typed != nullptr ? &typed->tree() : nullptr;
}

template const Bvh<BoundingSphere>* treeOf<BoundingSphere>(const MeshBvh&);
template const Bvh<Aabb>* treeOf<Aabb>(const MeshBvh&);
template const Bvh<Obb>* treeOf<Obb>(const MeshBvh&);
template const Bvh<Kdop<6>>* treeOf<Kdop<6>>(const MeshBvh&);
template const Bvh<Kdop<14>>* treeOf<Kdop<14>>(const MeshBvh&);
template const Bvh<Kdop<18>>* treeOf<Kdop<18>>(const MeshBvh&);
template const Bvh<Kdop<26>>* treeOf<Kdop<26>>(const MeshBvh&);
template const Bvh<Rss>* treeOf<Rss>(const MeshBvh&);
template const Bvh<Lss>* treeOf<Lss>(const MeshBvh&);

const Bvh<Obb>* obbTreeOf(const MeshBvh& tree) {
    if (const auto* wide = dynamic_cast<const MeshBvhWide*>(&tree)) return &wide->tree().binary();
    return treeOf<Obb>(tree);
}

const std::vector<std::string_view>& bvhVolumeNames() {
    static const std::vector<std::string_view> names = [] {
        std::vector<std::string_view> out;
        std::apply([&](auto... bv) { (out.push_back(BvName<decltype(bv)>::value), ...); },
                   BvhVolumeTypes{});
        out.push_back(kWideObbName);
        return out;
    }();
    return names;
}

std::unique_ptr<MeshBvh> buildMeshBvh(std::string_view volume_name, const TriangleMesh& mesh,
                                      const BvhBuildOptions& options) {
    if (volume_name == kWideObbName) return std::make_unique<MeshBvhWide>(mesh, options);
    std::unique_ptr<MeshBvh> out;
    std::apply(
        [&](auto... bv) {
            ((BvName<decltype(bv)>::value == volume_name && !out
                  ? (void)(out = std::make_unique<MeshBvhOf<decltype(bv)>>(mesh, options))
                  : (void)0),
             ...);
        },
        BvhVolumeTypes{});
    return out;
}

}  // namespace collision
