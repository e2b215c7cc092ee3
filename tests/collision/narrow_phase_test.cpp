// tests/collision/narrow_phase_test.cpp -- collide(): analytic cases, exact touching, swap
// symmetry, metamorphic (translate 1e6, scale 1e-4..1e4), closed forms against GJK on random
// pairs, meshes against brute force.
#include "collision/narrowphase/narrow_phase.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "collision/bvh/bvh.h"

// Private narrow-phase headers (collision/src is not on the test's include path).
#include "geometry/triangle_triangle.h"
#include "narrowphase/gjk.h"
#include "test_random.h"
#include "test_shapes.h"

namespace {

using collision::collide;
using collision::CollideOutput;
using collision::ContactState;
using collision::ConvexPolytope;
using collision::isColliding;
using collision::Pose;
using collision::Quat;
using collision::Real;
using collision::Shape;
using collision::ShapeType;
using collision::TriangleMesh;
using collision::Vec3;

const Real kSqrt2 = std::sqrt(Real(2));

Pose at(const Vec3& p, const Quat& q = Quat::Identity()) { return Pose{p, q}; }
Quat axisAngle(Real angle, const Vec3& axis) {
    return Quat(Eigen::AngleAxis<Real>(angle, axis.normalized()));
}

// A box as a hand-built polytope: 8 corners, 12 outward counter-clockwise triangles.
std::shared_ptr<ConvexPolytope> boxPolytope(const Vec3& h) {
    auto poly = std::make_shared<ConvexPolytope>();
    for (int i = 0; i < 8; ++i) {
        poly->vertices.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                                    (i & 4) ? h.z() : -h.z());
    }
    const std::array<std::array<int, 4>, 6> quads{
        {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}}};
    for (const auto& q : quads) {
        for (const std::array<int, 3> t :
             {std::array<int, 3>{q[0], q[1], q[2]}, std::array<int, 3>{q[0], q[2], q[3]}}) {
            const Vec3& a = poly->vertices[t[0]];
            const Vec3& b = poly->vertices[t[1]];
            const Vec3& c = poly->vertices[t[2]];
            const bool outward = (b - a).cross(c - a).dot(a + b + c) > 0;
            poly->faces.push_back(outward ? t : std::array<int, 3>{t[0], t[2], t[1]});
        }
    }
    return poly;
}

Shape boxHull(const Vec3& h) { return Shape::convexHull(boxPolytope(h)); }

Shape boxMesh(const Vec3& h) {
    auto poly = boxPolytope(h);
    auto mesh = std::make_shared<TriangleMesh>();
    mesh->vertices = poly->vertices;
    mesh->triangles = poly->faces;
    return Shape::triangleMesh(mesh, poly);
}

// A random triangle soup in [-1, 1]^3; its "hull" is the vertex set (enough for supports).
Shape randomSoup(cdlab_test::Rng& rng, int triangles) {
    auto mesh = std::make_shared<TriangleMesh>();
    for (int i = 0; i < triangles; ++i) {
        const Vec3 c = rng.vec(-0.8, 0.8);
        for (int k = 0; k < 3; ++k) mesh->vertices.push_back(c + rng.vec(-0.3, 0.3));
        mesh->triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
    }
    auto hull = std::make_shared<ConvexPolytope>();
    hull->vertices = mesh->vertices;
    return Shape::triangleMesh(mesh, hull);
}

// An irregular convex hull: box corners pushed around (still convex: a box with skewed extents
// per corner is not, so use a random affine image of a box).
Shape randomHull(cdlab_test::Rng& rng) {
    auto poly = boxPolytope(Vec3(1, 1, 1));
    Eigen::Matrix<Real, 3, 3> m = Eigen::Matrix<Real, 3, 3>::Identity();
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) m(i, j) += rng.uniform(-0.3, 0.3);
    }
    if (m.determinant() < 0) m.col(0) = -m.col(0);
    for (Vec3& v : poly->vertices) v = m * v * rng.uniform(0.4, 1.0);
    return Shape::convexHull(poly);
}

Shape randomShape(cdlab_test::Rng& rng, ShapeType type) {
    switch (type) {
        case ShapeType::Sphere:
            return Shape::sphere(rng.uniform(0.2, 1.0));
        case ShapeType::Box:
            return Shape::box(rng.vec(0.2, 1.0));
        case ShapeType::Capsule:
            return Shape::capsule(rng.uniform(0.1, 0.6), rng.uniform(0, 1));
        case ShapeType::ConvexHull:
            return randomHull(rng);
        case ShapeType::Mesh:
            return rng.integer(0, 1) ? randomSoup(rng, 12) : boxMesh(rng.vec(0.3, 1));
    }
    return Shape::sphere(1);
}

// ---- Analytic. ----

TEST(NarrowPhase, SphereSphereDistance) {
    const Shape a = Shape::sphere(1);
    const Shape b = Shape::sphere(0.5);
    const CollideOutput out = collide(a, at(Vec3(1, 2, 3)), b, at(Vec3(1, 5, 3)));
    EXPECT_EQ(out.state, ContactState::Separated);
    EXPECT_DOUBLE_EQ(out.distance, 1.5);
    EXPECT_EQ(collide(a, at(Vec3(0, 0, 0)), b, at(Vec3(0, 1.4, 0))).state,
              ContactState::Penetrating);
}

TEST(NarrowPhase, SphereBoxDistance) {
    const Shape box = Shape::box(Vec3(1, 1, 1));
    const Shape ball = Shape::sphere(1);
    CollideOutput out = collide(box, Pose{}, ball, at(Vec3(3, 3, 0)));
    EXPECT_EQ(out.state, ContactState::Separated);
    EXPECT_NEAR(out.distance, std::sqrt(Real(8)) - 1, 1e-14);
    // Box turned 45 degrees about z: its edge is sqrt(2) from the centre along x.
    out =
        collide(ball, at(Vec3(4, 0, 0)), box, at(Vec3::Zero(), axisAngle(M_PI / 4, Vec3::UnitZ())));
    EXPECT_EQ(out.state, ContactState::Separated);
    EXPECT_NEAR(out.distance, 3 - kSqrt2, 1e-14);
    EXPECT_EQ(collide(box, Pose{}, ball, at(Vec3(0.2, 0, 0))).state, ContactState::Penetrating);
}

TEST(NarrowPhase, CapsuleDistances) {
    const Shape cap = Shape::capsule(0.5, 1);
    // Parallel, side by side.
    CollideOutput out = collide(cap, Pose{}, cap, at(Vec3(3, 0.3, 0)));
    EXPECT_EQ(out.state, ContactState::Separated);
    EXPECT_NEAR(out.distance, 2, 1e-14);
    // Crossed: B along x, 2 above along z.
    out = collide(cap, Pose{}, cap, at(Vec3(0, 0, 2), axisAngle(M_PI / 2, Vec3::UnitZ())));
    EXPECT_NEAR(out.distance, 1, 1e-14);
    // End to end along y.
    out = collide(cap, Pose{}, cap, at(Vec3(0, 3.5, 0)));
    EXPECT_NEAR(out.distance, 0.5, 1e-14);
    // Sphere beside the capsule's cylinder and beyond its cap.
    out = collide(Shape::sphere(1), at(Vec3(2, 0.5, 0)), cap, Pose{});
    EXPECT_NEAR(out.distance, 0.5, 1e-14);
    out = collide(cap, Pose{}, Shape::sphere(1), at(Vec3(0, 4, 0)));
    EXPECT_NEAR(out.distance, 1.5, 1e-14);
    // Capsule against a box: beside it, and lying across its top.
    const Shape box = Shape::box(Vec3(1, 1, 1));
    out = collide(cap, at(Vec3(3, 0, 0)), box, Pose{});
    EXPECT_EQ(out.state, ContactState::Separated);
    EXPECT_NEAR(out.distance, 1.5, 1e-9);
    out = collide(box, Pose{}, cap, at(Vec3(0.3, 2, 0), axisAngle(M_PI / 2, Vec3::UnitZ())));
    EXPECT_NEAR(out.distance, 0.5, 1e-9);
}

TEST(NarrowPhase, BoxBoxKnownPoses) {
    const Shape box = Shape::box(Vec3(1, 1, 1));
    // Face to face.
    CollideOutput out = collide(box, Pose{}, box, at(Vec3(3, 0.5, -0.25)));
    EXPECT_EQ(out.state, ContactState::Separated);
    EXPECT_NEAR(out.distance, 1, 1e-9);
    // B's edge (turned 45 degrees about z) towards A's face.
    out = collide(box, Pose{}, box,
                  at(Vec3(1 + kSqrt2 + 0.5, 0, 0), axisAngle(M_PI / 4, Vec3::UnitZ())));
    EXPECT_NEAR(out.distance, 0.5, 1e-9);
    // Edge to edge, crossed: A's top edge along x at z = sqrt2, B's bottom edge along y.
    const Pose pose_a = at(Vec3::Zero(), axisAngle(M_PI / 4, Vec3::UnitX()));
    out = collide(box, pose_a, box,
                  at(Vec3(0, 0, 2 * kSqrt2 + 0.5), axisAngle(M_PI / 4, Vec3::UnitY())));
    EXPECT_EQ(out.state, ContactState::Separated);
    EXPECT_NEAR(out.distance, 0.5, 1e-9);
    EXPECT_EQ(collide(box, pose_a, box,
                      at(Vec3(0, 0, 2 * kSqrt2 - 0.1), axisAngle(M_PI / 4, Vec3::UnitY())))
                  .state,
              ContactState::Penetrating);
    EXPECT_EQ(collide(box, Pose{}, box, at(Vec3(1.5, 1.5, 0))).state, ContactState::Penetrating);
}

// ---- Touching. ----

TEST(NarrowPhase, ExactlyTouchingShapesAreTouching) {
    const Shape unit = Shape::box(Vec3(1, 1, 1));
    const Shape flat = Shape::box(Vec3(0.5, 2, 0.25));
    const Shape ball = Shape::sphere(1);
    const Shape cap = Shape::capsule(0.5, 1);
    const Shape hull = boxHull(Vec3(1, 1, 1));
    const Shape mesh = boxMesh(Vec3(1, 1, 1));
    const Quat quarter = axisAngle(M_PI / 2, Vec3::UnitX());
    struct Case {
        const char* what;
        const Shape* a;
        Pose pa;
        const Shape* b;
        Pose pb;
    };
    const std::vector<Case> cases{
        {"spheres", &ball, at(Vec3(0, 0, 0)), &ball, at(Vec3(2, 0, 0))},
        {"spheres diagonal", &ball, at(Vec3(1, 1, 1)), &ball, at(Vec3(1, 1, 3))},
        {"boxes face to face", &unit, Pose{}, &flat, at(Vec3(1.5, 0.7, 0.1))},
        {"boxes face to face, B quarter-turned", &unit, Pose{}, &flat,
         at(Vec3(1.5, 0, 0), quarter)},
        {"boxes edge on face", &unit, Pose{}, &unit,
         at(Vec3(1 + kSqrt2, 0, 0), axisAngle(M_PI / 4, Vec3::UnitZ()))},
        {"boxes corner to corner", &unit, Pose{}, &unit, at(Vec3(2, 2, 2))},
        {"sphere on box face", &ball, at(Vec3(0, 2, 0)), &unit, Pose{}},
        {"sphere on box corner", &ball, at(Vec3(1, 1, 1) + Vec3(1, 1, 1).normalized()), &unit,
         Pose{}},
        {"capsules side by side", &cap, Pose{}, &cap, at(Vec3(1, 0.5, 0))},
        {"capsule lying on box", &cap, at(Vec3(0, 1.5, 0), axisAngle(M_PI / 2, Vec3::UnitZ())),
         &unit, Pose{}},
        {"capsule standing on box", &cap, at(Vec3(0.2, 2.5, 0.3)), &unit, Pose{}},
        {"hull on box", &hull, at(Vec3(0, 2, 0)), &unit, Pose{}},
        {"hull on hull", &hull, at(Vec3(0.5, 0, 2)), &hull, Pose{}},
        {"sphere on hull", &ball, at(Vec3(0, 0, -2)), &hull, Pose{}},
        {"sphere on mesh", &ball, at(Vec3(0, 0, -2)), &mesh, Pose{}},
        {"box on mesh", &unit, at(Vec3(0.5, 2, 0.5)), &mesh, Pose{}},
        {"mesh on mesh", &mesh, at(Vec3(2, 0.25, 0)), &mesh, Pose{}},
        {"mesh on mesh corner", &mesh, at(Vec3(2, 2, 2)), &mesh, Pose{}},
    };
    for (const Case& c : cases) {
        EXPECT_EQ(collide(*c.a, c.pa, *c.b, c.pb).state, ContactState::Touching) << c.what;
        EXPECT_EQ(collide(*c.b, c.pb, *c.a, c.pa).state, ContactState::Touching) << c.what;
        // Moved apart by a small but real gap: Separated; pushed in: Penetrating.
        for (const Real gap : {Real(1e-9), Real(-1e-9)}) {
            Pose moved = c.pb;
            moved.position += gap * (c.pb.position - c.pa.position).normalized();
            const ContactState expected =
                gap > 0 ? ContactState::Separated : ContactState::Penetrating;
            EXPECT_EQ(collide(*c.a, c.pa, *c.b, moved).state, expected) << c.what << " " << gap;
        }
    }
}

TEST(NarrowPhase, MeshesAreSurfaces) {
    const Shape mesh = boxMesh(Vec3(2, 2, 2));
    const Shape ball = Shape::sphere(0.5);
    // Wholly inside the closed mesh: no triangle touches it.
    CollideOutput out = collide(mesh, Pose{}, ball, at(Vec3(0.1, 0.2, 0.3)));
    EXPECT_EQ(out.state, ContactState::Separated);
    EXPECT_EQ(out.triangle_tests, 0);  // culled: no triangle's box reaches the ball's box
    out = collide(mesh, Pose{}, ball, at(Vec3(1.8, 0, 0)));
    EXPECT_EQ(out.state, ContactState::Penetrating);
    EXPECT_GT(out.triangle_tests, 0);
    // A small mesh inside a large one: surfaces apart.
    EXPECT_EQ(collide(mesh, Pose{}, boxMesh(Vec3(0.5, 0.5, 0.5)), at(Vec3(0.3, 0, 0))).state,
              ContactState::Separated);
    EXPECT_EQ(collide(mesh, Pose{}, boxMesh(Vec3(0.5, 0.5, 0.5)), at(Vec3(2, 0, 0))).state,
              ContactState::Penetrating);
}

// ---- Symmetry and metamorphic. ----

struct RandomPair {
    Shape a, b;
    Pose pa, pb;
};

// Positions on a 1/1024 grid so that adding 1e6 is exact.
RandomPair randomPair(cdlab_test::Rng& rng, ShapeType ta, ShapeType tb, Real spread) {
    RandomPair p{randomShape(rng, ta), randomShape(rng, tb), Pose{}, Pose{}};
    auto grid = [](const Vec3& v) { return Vec3((v * 1024).array().round() / 1024); };
    p.pa = at(grid(rng.vec(-spread, spread)), rng.rotation());
    p.pb = at(grid(rng.vec(-spread, spread)), rng.rotation());
    return p;
}

void expectSame(const CollideOutput& x, const CollideOutput& y, const char* what) {
    EXPECT_EQ(x.state, y.state) << what;
    EXPECT_EQ(x.distance, y.distance) << what;
    EXPECT_EQ(x.triangle_tests, y.triangle_tests) << what;
    EXPECT_EQ(x.iterations, y.iterations) << what;
}

TEST(NarrowPhase, SwapAndTranslationGiveIdenticalOutputs) {
    cdlab_test::Rng rng(99);
    int colliding = 0;
    int total = 0;
    for (int ta = 0; ta < collision::kShapeTypeCount; ++ta) {
        for (int tb = 0; tb < collision::kShapeTypeCount; ++tb) {
            for (int n = 0; n < 60; ++n) {
                const RandomPair p = randomPair(rng, ShapeType(ta), ShapeType(tb), 1.2);
                const CollideOutput ab = collide(p.a, p.pa, p.b, p.pb);
                ASSERT_NE(ab.state, ContactState::Failed);
                expectSame(ab, collide(p.b, p.pb, p.a, p.pa), "swap");
                const Vec3 far(1e6, -1e6, 1e6);
                expectSame(ab,
                           collide(p.a, at(p.pa.position + far, p.pa.orientation), p.b,
                                   at(p.pb.position + far, p.pb.orientation)),
                           "translate");
                colliding += isColliding(ab.state);
                ++total;
            }
        }
    }
    EXPECT_GT(colliding, total / 4);
    EXPECT_LT(colliding, 3 * total / 4);
}

TEST(NarrowPhase, ScalingKeepsTheState) {
    cdlab_test::Rng rng(314);
    int checked = 0;
    for (int ta = 0; ta < collision::kShapeTypeCount; ++ta) {
        for (int tb = 0; tb < collision::kShapeTypeCount; ++tb) {
            for (int n = 0; n < 40; ++n) {
                const RandomPair p = randomPair(rng, ShapeType(ta), ShapeType(tb), 1.2);
                const CollideOutput base = collide(p.a, p.pa, p.b, p.pb);
                // Powers of two scale every rounding exactly: identical state, scaled distance.
                for (const Real k : {std::ldexp(Real(1), -13), std::ldexp(Real(1), 13)}) {
                    const CollideOutput s =
                        collide(cdlab_test::scaledShape(p.a, k), at(p.pa.position * k, p.pa.orientation),
                                cdlab_test::scaledShape(p.b, k), at(p.pb.position * k, p.pb.orientation));
                    EXPECT_EQ(s.state, base.state);
                    EXPECT_NEAR(s.distance, base.distance * k, 1e-12 * k);
                }
                // 1e-4 and 1e4 round differently; away from the boundary the state stays.
                if (base.state == ContactState::Touching ||
                    (base.state == ContactState::Separated && base.distance < 1e-6)) {
                    continue;
                }
                for (const Real k : {Real(1e-4), Real(1e4)}) {
                    const CollideOutput s =
                        collide(cdlab_test::scaledShape(p.a, k), at(p.pa.position * k, p.pa.orientation),
                                cdlab_test::scaledShape(p.b, k), at(p.pb.position * k, p.pb.orientation));
                    EXPECT_EQ(s.state, base.state) << ta << " " << tb << " " << n;
                    EXPECT_NEAR(s.distance, base.distance * k, 1e-9 * k);
                }
                ++checked;
            }
        }
    }
    EXPECT_GT(checked, 700);  // mesh pairs report no distance and are skipped when Separated
}

TEST(NarrowPhase, TouchingSurvivesTranslationAndScaling) {
    // Touching is decided to kTouchRelativeTolerance of the shapes' size, so the poses must carry
    // the contact exactly: far from the origin that needs power-of-two sizes (a 1e-4 box at 1e6
    // has a position ulp of 1e-10, a million times its touching tolerance).
    const Shape unit = Shape::box(Vec3(1, 1, 1));
    const Shape mesh = boxMesh(Vec3(1, 1, 1));
    const std::array<std::array<Real, 2>, 8> setups{{{1e-4, 0},
                                                     {1, 0},
                                                     {1e4, 0},
                                                     {std::ldexp(Real(1), -13), 0},
                                                     {std::ldexp(Real(1), -13), 1e6},
                                                     {1, 1e6},
                                                     {std::ldexp(Real(1), 13), 1e6},
                                                     {1e4, 1e6}}};
    for (const auto& setup : setups) {
        const Real k = setup[0];
        const Real shift = setup[1];
        {
            const Vec3 o(shift, shift, -shift);
            EXPECT_EQ(
                collide(cdlab_test::scaledShape(unit, k), at(o), cdlab_test::scaledShape(unit, k), at(o + Vec3(2 * k, 0, 0))).state,
                ContactState::Touching)
                << k << " " << shift;
            EXPECT_EQ(
                collide(cdlab_test::scaledShape(mesh, k), at(o), cdlab_test::scaledShape(mesh, k), at(o + Vec3(0, 2 * k, 0))).state,
                ContactState::Touching)
                << k << " " << shift;
            EXPECT_EQ(
                collide(Shape::sphere(k), at(o), Shape::sphere(k), at(o + Vec3(0, 0, 2 * k))).state,
                ContactState::Touching)
                << k << " " << shift;
        }
    }
}

// ---- Differential: closed forms against the generic GJK entry. ----

TEST(NarrowPhase, ClosedFormsAgreeWithGjk) {
    const std::array<std::array<ShapeType, 2>, 6> pairs{{{ShapeType::Sphere, ShapeType::Sphere},
                                                         {ShapeType::Sphere, ShapeType::Box},
                                                         {ShapeType::Sphere, ShapeType::Capsule},
                                                         {ShapeType::Capsule, ShapeType::Capsule},
                                                         {ShapeType::Capsule, ShapeType::Box},
                                                         {ShapeType::Box, ShapeType::Box}}};
    // Position spreads that put each pair type near half colliding.
    const std::array<Real, 6> spread{1.1, 1.1, 1.0, 0.9, 1.1, 1.1};
    cdlab_test::Rng rng(4242);
    for (const auto& types : pairs) {
        int colliding = 0;
        const int kPairs = 3000;
        for (int n = 0; n < kPairs; ++n) {
            const RandomPair p = randomPair(rng, types[0], types[1], spread[&types - &pairs[0]]);
            const CollideOutput closed = collide(p.a, p.pa, p.b, p.pb);
            const Real scale = std::max(collision::ConvexCore::fromShape(p.a).boundingRadius(),
                                        collision::ConvexCore::fromShape(p.b).boundingRadius());
            const CollideOutput gjk = collision::collideConvexCores(
                collision::ConvexCore::fromShape(p.a), collision::ConvexCore::fromShape(p.b),
                collision::relativePose(p.pa, p.pb), collision::kTouchRelativeTolerance * scale,
                scale);
            ASSERT_EQ(closed.state, gjk.state) << int(types[0]) << int(types[1]) << " #" << n;
            ASSERT_NEAR(closed.distance, gjk.distance, 1e-9 * scale)
                << int(types[0]) << int(types[1]) << " #" << n;
            colliding += isColliding(closed.state);
        }
        // The random set must exercise both answers.
        EXPECT_GT(colliding, kPairs * 3 / 10) << int(types[0]) << int(types[1]);
        EXPECT_LT(colliding, kPairs * 7 / 10) << int(types[0]) << int(types[1]);
    }
}

TEST(NarrowPhase, BoxAgreesWithItsHull) {
    cdlab_test::Rng rng(17);
    int colliding = 0;
    const int kPairs = 3000;
    for (int n = 0; n < kPairs; ++n) {
        const Vec3 ha = rng.vec(0.2, 1);
        const Vec3 hb = rng.vec(0.2, 1);
        const Pose pa = at(rng.vec(-1, 1), rng.rotation());
        const Pose pb = at(rng.vec(-1, 1), rng.rotation());
        const CollideOutput boxes = collide(Shape::box(ha), pa, Shape::box(hb), pb);
        const CollideOutput hulls = collide(boxHull(ha), pa, boxHull(hb), pb);
        const CollideOutput mixed = collide(Shape::box(ha), pa, boxHull(hb), pb);
        ASSERT_EQ(boxes.state, hulls.state) << n;
        ASSERT_EQ(boxes.state, mixed.state) << n;
        ASSERT_NEAR(boxes.distance, hulls.distance, 1e-9) << n;
        colliding += isColliding(boxes.state);
    }
    EXPECT_GT(colliding, kPairs * 3 / 10);
    EXPECT_LT(colliding, kPairs * 7 / 10);
}

// ---- Meshes against brute force. ----

TEST(NarrowPhase, MeshConvexMatchesSurfaceDistance) {
    // A ball collides with a closed box mesh iff its centre is within r of the box's surface.
    cdlab_test::Rng rng(8);
    const Vec3 h(1, 0.7, 0.5);
    const Shape mesh = boxMesh(h);
    int colliding = 0;
    const int kPairs = 3000;
    for (int n = 0; n < kPairs; ++n) {
        const Real r = rng.uniform(0.05, 0.4);
        const Pose pm = at(rng.vec(-1, 1), rng.rotation());
        const Vec3 local = rng.vec(-1.3, 1.3);
        const Vec3 c = pm.apply(local);
        const Vec3 q = local.cwiseMax(-h).cwiseMin(h);
        const Real to_surface =
            (local - q).isZero() ? (h - local.cwiseAbs()).minCoeff() : (local - q).norm();
        const CollideOutput out = collide(mesh, pm, Shape::sphere(r), at(c));
        ASSERT_EQ(isColliding(out.state), to_surface <= r) << n;
        colliding += isColliding(out.state);
    }
    EXPECT_GT(colliding, kPairs * 3 / 10);
    EXPECT_LT(colliding, kPairs * 7 / 10);
}

TEST(NarrowPhase, MeshMeshMatchesBruteForce) {
    cdlab_test::Rng rng(77);
    int colliding = 0;
    int culled_some = 0;
    const int kPairs = 400;
    for (int n = 0; n < kPairs; ++n) {
        const Shape a = randomSoup(rng, 16);
        const Shape b = randomSoup(rng, 16);
        const Pose pa = at(rng.vec(-0.8, 0.8), rng.rotation());
        const Pose pb = at(rng.vec(-0.8, 0.8), rng.rotation());
        // Brute force in world coordinates, every pair.
        bool expected = false;
        for (const auto& ta : a.mesh->triangles) {
            for (const auto& tb : b.mesh->triangles) {
                expected =
                    expected ||
                    collision::testTriangleTriangle(
                        pa.apply(a.mesh->vertices[ta[0]]), pa.apply(a.mesh->vertices[ta[1]]),
                        pa.apply(a.mesh->vertices[ta[2]]), pb.apply(b.mesh->vertices[tb[0]]),
                        pb.apply(b.mesh->vertices[tb[1]]), pb.apply(b.mesh->vertices[tb[2]]));
            }
        }
        const CollideOutput out = collide(a, pa, b, pb);
        ASSERT_EQ(isColliding(out.state), expected) << n;
        EXPECT_LE(out.triangle_tests, 16 * 16);
        culled_some += out.triangle_tests < 16 * 16;
        colliding += expected;
    }
    EXPECT_GT(colliding, kPairs * 3 / 10);
    EXPECT_LT(colliding, kPairs * 7 / 10);
    EXPECT_GT(culled_some, kPairs / 2);
}

TEST(NarrowPhase, NonFiniteInputFails) {
    const Shape ball = Shape::sphere(1);
    EXPECT_EQ(collide(ball, at(Vec3(NAN, 0, 0)), ball, Pose{}).state, ContactState::Failed);
    EXPECT_EQ(collide(Shape::sphere(INFINITY), Pose{}, ball, Pose{}).state, ContactState::Failed);
}

}  // namespace
