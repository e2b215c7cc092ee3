// tests/collision/bvh_self_test.cpp -- self-collision of one mesh (intersectSelf, every volume
// type) against the brute-force loop on adversarial meshes: a sheet folded onto itself (coplanar
// and coincident, just apart, crossing), triangle soups with shared and repeated vertex indices
// and degenerate triangles, far from the origin, at tiny and huge scales.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

#include "collision/bvh/bvh.h"
#include "test_random.h"
#include "bvh_typed_tests.h"

namespace {

using collision::Bvh;
using collision::BvhBuildOptions;
using collision::BvhSplit;
using collision::BvhVolumeTypes;
using collision::BvName;
using collision::Real;
using collision::TriangleMesh;
using collision::TrianglePair;
using collision::Vec3;

// A strip of 2m x n grid cells in the plane y = 0, x in [0, 2], z in [0, 1], folded back at
// x = 1 like a hairpin: column m + k lies over column m - k at height h + s (k dx - 1/2). With
// h = s = 0 the upper half lies exactly on the lower half, on coincident vertices with other
// indices (not adjacent, so their pairs count); h > 0, s = 0 holds the halves just apart; s != 0
// tilts the upper half through the lower one.
//
//      upper half  ____________
//                 /             (fold at x = 1: the fold column is shared, so the cells
//      lower half \____________  beside it are adjacent and excluded)
TriangleMesh foldedSheet(int m, int n, Real h, Real s) {
    TriangleMesh mesh;
    const Real dx = Real(1) / m;
    for (int i = 0; i <= 2 * m; ++i) {
        for (int j = 0; j <= n; ++j) {
            const Real z = Real(j) / n;
            if (i <= m) {
                mesh.vertices.emplace_back(i * dx, 0, z);
            } else {
                const Real d = (i - m) * dx;
                mesh.vertices.emplace_back(1 - d, h + s * (d - Real(0.5)), z);
            }
        }
    }
    auto id = [&](int i, int j) { return static_cast<std::int32_t>(i * (n + 1) + j); };
    for (int i = 0; i < 2 * m; ++i) {
        for (int j = 0; j < n; ++j) {
            mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    }
    return mesh;
}

// Random triangles in the unit cube whose corners are drawn from a small pool of vertices, so
// many share a vertex index (adjacent) and some repeat one (degenerate); plus a few collinear
// (zero-area) triangles on fresh vertices.
TriangleMesh triangleSoup(std::uint64_t seed, int triangles, int pool) {
    cdlab_test::Rng rng(seed);
    TriangleMesh mesh;
    for (int i = 0; i < pool; ++i) mesh.vertices.push_back(rng.vec(0, 1));
    for (int t = 0; t < triangles; ++t) {
        mesh.triangles.push_back(
            {rng.integer(0, pool - 1), rng.integer(0, pool - 1), rng.integer(0, pool - 1)});
    }
    for (int t = 0; t < 4; ++t) {
        const Vec3 a = rng.vec(0, 1);
        const Vec3 b = rng.vec(0, 1);
        const auto base = static_cast<std::int32_t>(mesh.vertices.size());
        mesh.vertices.push_back(a);
        mesh.vertices.push_back(b);
        mesh.vertices.push_back(Real(0.5) * (a + b));  // on the segment: zero area
        mesh.triangles.push_back({base, base + 1, base + 2});
    }
    return mesh;
}

TriangleMesh transformed(TriangleMesh mesh, Real scale, const Vec3& offset) {
    for (Vec3& v : mesh.vertices) v = scale * v + offset;
    return mesh;
}

struct Case {
    std::string name;
    TriangleMesh mesh;
};

std::vector<Case> adversarialMeshes() {
    std::vector<Case> base = {
        {"sheet folded flat onto itself", foldedSheet(6, 4, 0, 0)},
        {"sheet folded just apart", foldedSheet(6, 4, Real(1) / 1024, 0)},
        {"sheet folded through itself", foldedSheet(6, 4, 0, Real(0.25))},
        {"sheet folded into a V: meets itself only at the fold", foldedSheet(8, 3, 0.25, 0.5)},
        {"soup, many shared vertices", triangleSoup(17, 60, 24)},
        {"soup, few shared vertices", triangleSoup(29, 80, 200)},
    };
    std::vector<Case> all;
    for (const Case& c : base) {
        all.push_back(c);
        all.push_back(
            {c.name + ", translated by 1e6", transformed(c.mesh, 1, Vec3(1e6, -1e6, 1e6))});
        all.push_back({c.name + ", scaled by 1e-4", transformed(c.mesh, 1e-4, Vec3::Zero())});
        all.push_back({c.name + ", scaled by 1e4", transformed(c.mesh, 1e4, Vec3::Zero())});
    }
    return all;
}

const std::vector<Case>& cases() {
    static const std::vector<Case> c = adversarialMeshes();
    return c;
}

const std::vector<std::vector<TrianglePair>>& bruteAnswers() {
    static const std::vector<std::vector<TrianglePair>> answers = [] {
        std::vector<std::vector<TrianglePair>> a;
        for (const Case& c : cases()) a.push_back(collision::intersectSelfBruteForce(c.mesh));
        return a;
    }();
    return answers;
}

template <class BV>
class BvhSelf : public ::testing::Test {};
TYPED_TEST_SUITE(BvhSelf, BvhVolumeTestTypes, BvhVolumeTestName);

TYPED_TEST(BvhSelf, AdversarialMeshesMatchBruteForce) {
    int non_empty = 0;
    for (std::size_t k = 0; k < cases().size(); ++k) {
        const Case& c = cases()[k];
        const std::vector<TrianglePair>& brute = bruteAnswers()[k];
        EXPECT_EQ(collision::intersectSelf(Bvh<TypeParam>(c.mesh)), brute) << c.name;
        // Leaves of several triangles hold adjacent ones together: still excluded.
        EXPECT_EQ(
            collision::intersectSelf(Bvh<TypeParam>(c.mesh, BvhBuildOptions{BvhSplit::Mean, 3})),
            brute)
            << c.name;
        non_empty += !brute.empty();
    }
    // Both outcomes occur.
    EXPECT_GT(non_empty, 0);
    EXPECT_LT(non_empty, static_cast<int>(cases().size()));
}

TEST(BvhSelfReference, FoldedSheetAnswersAsDrawn) {
    // Flat fold: every lower triangle meets the upper triangles over it, on coincident vertices
    // that are not shared (so not adjacent): pairs exist away from the fold.
    EXPECT_FALSE(collision::intersectSelfBruteForce(foldedSheet(6, 4, 0, 0)).empty());
    // Held 1/1024 apart: nothing.
    EXPECT_TRUE(collision::intersectSelfBruteForce(foldedSheet(6, 4, Real(1) / 1024, 0)).empty());
    // A flat sheet alone: every touching pair shares a vertex.
    TriangleMesh flat = foldedSheet(6, 4, 0, 0);
    flat.triangles.resize(flat.triangles.size() / 2);
    EXPECT_TRUE(collision::intersectSelfBruteForce(flat).empty());
    // Powers of two scale exactly: the same pairs as unscaled.
    EXPECT_EQ(collision::intersectSelfBruteForce(
                  transformed(foldedSheet(6, 4, 0, 0.25), Real(1) / 8192, Vec3::Zero())),
              collision::intersectSelfBruteForce(foldedSheet(6, 4, 0, 0.25)));
}

TEST(BvhSelfReference, SharedIndicesAreAdjacentCoincidentCopiesAreNot) {
    // Two triangles crossing at a common corner: adjacent when the corner is one index, a pair
    // when it is two coincident vertices.
    TriangleMesh shared;
    shared.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, -1)};
    shared.triangles = {{0, 1, 2}, {0, 3, 4}};
    EXPECT_TRUE(collision::intersectSelfBruteForce(shared).empty());
    TriangleMesh copied = shared;
    copied.vertices.push_back(Vec3(0, 0, 0));
    copied.triangles[1][0] = 5;
    const std::vector<TrianglePair> expected = {{0, 1}};
    EXPECT_EQ(collision::intersectSelfBruteForce(copied), expected);
    EXPECT_EQ(collision::intersectSelf(Bvh<collision::Obb>(copied)), expected);
}

}  // namespace
