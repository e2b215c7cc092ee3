// Mesh-mesh time of impact (timeOfImpactMeshes): never later than the first contact found by
// dense sampling of the exact discrete test, close to it at the reported time, and a ring
// passing around a rod is not stopped (its convex hull would be).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "collision/bvh/bvh.h"
#include "collision/ccd/ccd.h"
#include "collision/geometry/convex_hull.h"
#include "collision/geometry/shape.h"
#include "test_meshes.h"
#include "test_random.h"

namespace collision {
namespace {

using cdlab_test::makeTorusMesh;
using cdlab_test::Rng;

// First sample k/n (k = 0..n) at which the meshes touch or cross (exact triangle tests at the
// sampled poses), or 2 when no sample does.
Real firstSampledContact(const Bvh<Obb>& a, const Sweep& sa, const Bvh<Obb>& b, const Sweep& sb,
                         int n) {
    for (int k = 0; k <= n; ++k) {
        const Real t = Real(k) / n;
        const Pose b_in_a = sa.at(t).inverse() * sb.at(t);
        if (testBvhBvh(a, b, b_in_a)) return t;
    }
    return 2;
}

TEST(MeshTimeOfImpact, NeverLaterThanSampledContactAndCloseAtTheReportedTime) {
    const TriangleMesh torus = makeTorusMesh(1.0, 0.3, 24, 12);  // 576 triangles
    const Bvh<Obb> tree(torus);
    Rng rng(11);
    int hits = 0;
    int separated = 0;
    for (int trial = 0; trial < 40; ++trial) {
        Sweep sa;
        sa.start.position = Vec3::Zero();
        sa.start.orientation = rng.rotation();
        sa.rotation = rng.vec(-1.5, 1.5);
        Sweep sb;
        sb.start.position = rng.vec(-1, 1).normalized() * 4.0;
        sb.start.orientation = rng.rotation();
        // Aim B at A's neighbourhood: some sweeps hit, some miss.
        sb.translation = -sb.start.position + rng.vec(-2.0, 2.0);
        sb.rotation = rng.vec(-1.5, 1.5);
        sb.spin = rng.vec(-1.0, 1.0);
        MeshToiInput in;
        in.a = &tree;
        in.b = &tree;
        in.sweep_a = sa;
        in.sweep_b = sb;
        const MeshToiOutput r = timeOfImpactMeshes(in);
        ASSERT_NE(r.toi.state, CcdState::Failed) << "trial " << trial;
        ASSERT_NE(r.toi.state, CcdState::Overlapped) << "trial " << trial;
        const Real sampled = firstSampledContact(tree, sa, tree, sb, 400);
        if (r.toi.state == CcdState::Separated) {
            ++separated;
            // Separated claims no contact on the whole step: no sample may touch.
            EXPECT_EQ(sampled, 2) << "trial " << trial;
            continue;
        }
        ++hits;
        // Conservative: not after the first sampled contact.
        EXPECT_LE(r.toi.t, sampled) << "trial " << trial;
        // Tight: at the reported time the surfaces are within the acceptance tolerance
        // (kToiRelativeTolerance of the triangles' bounding radius about the mesh origin, <= 1.3
        // here) plus rounding.
        const Pose b_in_a = sa.at(r.toi.t).inverse() * sb.at(r.toi.t);
        const MeshDistance d = distanceBvhBvh(tree, tree, b_in_a);
        EXPECT_LE(d.distance, kToiRelativeTolerance * 1.3 + 1e-9) << "trial " << trial;
        // The witness triangles are the pair that is that close.
        ASSERT_GE(r.triangle_a, 0);
        ASSERT_GE(r.triangle_b, 0);
        // Culling did its work: far fewer triangle advancements than triangle pairs.
        EXPECT_LT(r.triangle_queries, std::int64_t(576) * 576 / 20) << "trial " << trial;
    }
    // Both outcomes must occur, or the test proves little.
    EXPECT_GE(hits, 8);
    EXPECT_GE(separated, 8);
}

// A ring flying along its axis around a thin rod (threaded through the hole): the meshes never
// touch, so mesh CCD reports Separated, while conservative advancement on the convex hulls
// (which contain the rod's path) stops the ring.
//
//        rod (along z, through the hole)
//         |
//      ( (|) )  ring, moving along z
//         |
TEST(MeshTimeOfImpact, RingAroundRodIsNotStoppedButItsHullIs) {
    const TriangleMesh ring_mesh = makeTorusMesh(1.0, 0.2, 32, 12);
    const TriangleMesh rod_mesh = makeTorusMesh(0.05, 0.02, 8, 6);  // a small ring as the "rod"
    const Bvh<Obb> ring(ring_mesh);
    const Bvh<Obb> rod(rod_mesh);
    Sweep s_ring;
    s_ring.start.position = Vec3(0, 0, -3);
    s_ring.translation = Vec3(0, 0, 6);
    Sweep s_rod;  // at rest at the origin, inside the hole
    MeshToiInput in;
    in.a = &ring;
    in.b = &rod;
    in.sweep_a = s_ring;
    in.sweep_b = s_rod;
    const MeshToiOutput r = timeOfImpactMeshes(in);
    EXPECT_EQ(r.toi.state, CcdState::Separated);
    EXPECT_EQ(firstSampledContact(ring, s_ring, rod, s_rod, 200), 2);

    const Shape ring_hull = Shape::convexHull(
        std::make_shared<ConvexPolytope>(computeConvexHull(ring_mesh.vertices).hull));
    const Shape rod_hull = Shape::convexHull(
        std::make_shared<ConvexPolytope>(computeConvexHull(rod_mesh.vertices).hull));
    ToiInput hull_in;
    hull_in.a = &ring_hull;
    hull_in.b = &rod_hull;
    hull_in.sweep_a = s_ring;
    hull_in.sweep_b = s_rod;
    EXPECT_EQ(timeOfImpact(hull_in).state, CcdState::Hit);

    // Shifted sideways so the rod meets the tube: now the mesh query stops the ring, before
    // the first sampled contact.
    s_rod.start.position = Vec3(1.0, 0, 0);
    in.sweep_b = s_rod;
    const MeshToiOutput hit = timeOfImpactMeshes(in);
    ASSERT_EQ(hit.toi.state, CcdState::Hit);
    EXPECT_LE(hit.toi.t, firstSampledContact(ring, s_ring, rod, s_rod, 2000));
    EXPECT_GT(hit.toi.t, 0.3);  // the tube's near face is at z = -0.2 - 0.02: t ~ 0.46
}

// Regression (review): the node test proved boxes apart without the target gap, so a pair whose
// gap closed to target_gap without the boxes ever overlapping was dropped: Separated instead of
// Hit. Two unit quads (flat OBBs), B sliding over A 0.01 above it, target gap 0.05:
//
//        B [====]  -->            gap 0.05 reached when B's edge is 0.049 from A's (x)
//   A [====]                      t = (1 - 0.049) / 6 = 0.1585
//
TEST(MeshTimeOfImpact, TargetGapIsReachedWithoutTheBoxesOverlapping) {
    TriangleMesh quad;
    quad.vertices = {Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(1, 1, 0), Vec3(-1, 1, 0)};
    quad.triangles = {{0, 1, 2}, {0, 2, 3}};
    const Bvh<Obb> tree(quad);
    MeshToiInput in;
    in.a = &tree;
    in.b = &tree;
    in.sweep_b.start.position = Vec3(3, 0, 0.01);
    in.sweep_b.translation = Vec3(-6, 0, 0);
    in.target_gap = 0.05;
    const MeshToiOutput r = timeOfImpactMeshes(in);
    ASSERT_EQ(r.toi.state, CcdState::Hit);
    const Real exact = (1 - std::sqrt(0.05 * 0.05 - 0.01 * 0.01)) / 6;
    EXPECT_LE(r.toi.t, exact + 1e-12);
    // Accepted within target gap + tolerance (1e-3 of the triangles' radius about the origin,
    // sqrt(2)), closing at up to 6 m per step.
    EXPECT_GE(r.toi.t, exact - (1e-3 * std::sqrt(2.0) + 1e-9) / 6 * 2);
    in.target_gap = 0;  // without a target gap the quads never touch
    EXPECT_EQ(timeOfImpactMeshes(in).toi.state, CcdState::Separated);
}

TEST(MeshTimeOfImpact, NullTreesFailAndEmptyStepIsSeparated) {
    MeshToiInput in;
    EXPECT_EQ(timeOfImpactMeshes(in).toi.state, CcdState::Failed);
    const TriangleMesh torus = makeTorusMesh(1.0, 0.3, 8, 6);
    const Bvh<Obb> tree(torus);
    in.a = &tree;
    in.b = &tree;
    in.sweep_b.start.position = Vec3(10, 0, 0);
    const MeshToiOutput r = timeOfImpactMeshes(in);
    EXPECT_EQ(r.toi.state, CcdState::Separated);
    EXPECT_EQ(r.triangle_queries, 0);  // the root pair is culled
}

}  // namespace
}  // namespace collision
