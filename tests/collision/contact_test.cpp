// tests/collision/contact_test.cpp -- contact(): depth/distance, normal, witnesses, features and
// manifold against closed forms (sphere-sphere, sphere-box, axis-aligned box-box,
// capsule-capsule) on random pairs that collide 30-70 % of the time; GJK/EPA (boxes and spheres
// given as hulls) against the same closed forms and against box-box SAT; mirror symmetry,
// agreement with collide(), exact touching, metamorphic translation and scaling.
#include "collision/narrowphase/contact.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <memory>
#include <vector>

#include "collision/geometry/convex_hull.h"
#include "collision/narrowphase/contact_reference.h"
#include "collision/narrowphase/narrow_phase.h"
// Private narrow-phase headers (collision/src is on the test include path) for the caps.
#include "narrowphase/epa.h"
#include "test_random.h"
#include "test_shapes.h"

namespace {

using cdlab_test::boundingRadius;

using collision::collide;
using collision::contact;
using collision::CollideOutput;
using collision::ContactOutput;
using collision::ContactState;
using collision::ConvexPolytope;
using collision::Feature;
using collision::FeatureType;
using collision::isColliding;
using collision::Pose;
using collision::Quat;
using collision::Real;
using collision::Shape;
using collision::ShapeType;
using collision::Vec3;

Pose at(const Vec3& p, const Quat& q = Quat::Identity()) { return Pose{p, q}; }

Quat axisAngle(Real angle, const Vec3& axis) {
    return Quat(Eigen::AngleAxis<Real>(angle, axis.normalized()));
}

std::shared_ptr<const ConvexPolytope> hullOf(const std::vector<Vec3>& points) {
    const auto out = collision::computeConvexHull(points);
    EXPECT_TRUE(out.ok) << out.error;
    return std::make_shared<const ConvexPolytope>(out.hull);
}

// A box as a convex hull: contact() then takes the generic GJK/EPA path instead of SAT.
Shape boxHull(const Vec3& h) {
    std::vector<Vec3> corners;
    for (int i = 0; i < 8; ++i) {
        corners.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                             (i & 4) ? h.z() : -h.z());
    }
    return Shape::convexHull(hullOf(corners));
}

// Signed distance of a world point from the shape's surface (0 on it, < 0 inside); exact for
// sphere, box, capsule; for hulls the largest face-plane distance (0 exactly on the boundary).
Real surfaceDistance(const Shape& s, const Pose& pose, const Vec3& world) {
    const Vec3 p = pose.applyInverse(world);
    switch (s.type) {
        case ShapeType::Sphere:
            return p.norm() - s.radius;
        case ShapeType::Box: {
            const Vec3 d = p.cwiseAbs() - s.half_extents;
            return d.cwiseMax(0).norm() + std::min(d.maxCoeff(), Real(0));
        }
        case ShapeType::Capsule: {
            const Vec3 q(0, std::clamp(p.y(), -s.half_height, s.half_height), 0);
            return (p - q).norm() - s.radius;
        }
        case ShapeType::ConvexHull:
        case ShapeType::Mesh: {
            Real m = -std::numeric_limits<Real>::infinity();
            for (const auto& f : s.hull->faces) {
                const Vec3& a = s.hull->vertices[static_cast<std::size_t>(f[0])];
                const Vec3 n = (s.hull->vertices[static_cast<std::size_t>(f[1])] - a)
                                   .cross(s.hull->vertices[static_cast<std::size_t>(f[2])] - a)
                                   .normalized();
                m = std::max(m, n.dot(p - a));
            }
            return m;
        }
    }
    return 0;
}

// Checks every output invariant of contact.h that holds for any pair: finite, unit normal,
// witnesses on the surfaces, point_b - point_a = signed_distance * normal (both tolerances
// relative to the scale and the distance from the origin), manifold within the state's rules.
void expectConsistent(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb,
                      const ContactOutput& out, Real rel_tol, const char* what, int n) {
    ASSERT_NE(out.state, ContactState::Failed) << what << " " << n;
    const Real scale = std::max(boundingRadius(a), boundingRadius(b));
    const Real far = std::max(pa.position.norm(), pb.position.norm());
    const Real tol = rel_tol * scale + Real(64) * collision::kEpsilon * far;
    ASSERT_TRUE(out.normal.allFinite() && out.point_a.allFinite() && out.point_b.allFinite())
        << what << " " << n;
    ASSERT_NEAR(out.normal.norm(), 1, 1e-12) << what << " " << n;
    ASSERT_NEAR(surfaceDistance(a, pa, out.point_a), 0, tol) << what << " " << n;
    ASSERT_NEAR(surfaceDistance(b, pb, out.point_b), 0, tol) << what << " " << n;
    const Vec3 gap = out.point_b - out.point_a;
    ASSERT_LE((gap - out.signed_distance * out.normal).norm(), tol) << what << " " << n;
    if (out.state == ContactState::Separated) {
        ASSERT_EQ(out.manifold_size, 0) << what << " " << n;
        ASSERT_GT(out.signed_distance, 0) << what << " " << n;
    } else {
        ASSERT_GE(out.manifold_size, 1) << what << " " << n;
        ASSERT_LE(out.manifold_size, 4) << what << " " << n;
        for (int i = 0; i < out.manifold_size; ++i) {
            const auto& m = out.manifold[static_cast<std::size_t>(i)];
            ASSERT_GE(m.depth, 0) << what << " " << n;
            ASSERT_LE(m.depth, -out.signed_distance + tol) << what << " " << n;
            ASSERT_NEAR(surfaceDistance(a, pa, m.point_a), 0, tol) << what << " " << n;
            ASSERT_NEAR(surfaceDistance(b, pb, m.point_b), 0, tol) << what << " " << n;
        }
    }
}

// contact(b, a) must be the exact mirror of contact(a, b).
void expectMirror(const ContactOutput& ab, const ContactOutput& ba, int n) {
    ASSERT_EQ(ab.state, ba.state) << n;
    ASSERT_EQ(ab.signed_distance, ba.signed_distance) << n;
    ASSERT_EQ(ab.normal, Vec3(-ba.normal)) << n;
    ASSERT_EQ(ab.point_a, ba.point_b) << n;
    ASSERT_EQ(ab.point_b, ba.point_a) << n;
    ASSERT_EQ(ab.feature_a.type, ba.feature_b.type) << n;
    ASSERT_EQ(ab.feature_a.index, ba.feature_b.index) << n;
    ASSERT_EQ(ab.feature_b.type, ba.feature_a.type) << n;
    ASSERT_EQ(ab.feature_b.index, ba.feature_a.index) << n;
    ASSERT_EQ(ab.manifold_size, ba.manifold_size) << n;
    for (int i = 0; i < ab.manifold_size; ++i) {
        const auto k = static_cast<std::size_t>(i);
        ASSERT_EQ(ab.manifold[k].point_a, ba.manifold[k].point_b) << n;
        ASSERT_EQ(ab.manifold[k].point_b, ba.manifold[k].point_a) << n;
        ASSERT_EQ(ab.manifold[k].depth, ba.manifold[k].depth) << n;
    }
}

// ---- Closed-form references ----

Real pointBoxSignedDistance(const Vec3& p, const Vec3& h) {
    const Vec3 d = p.cwiseAbs() - h;
    return d.cwiseMax(0).norm() + std::min(d.maxCoeff(), Real(0));
}

Real pointSegmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
    const Vec3 ab = b - a;
    const Real t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), Real(0), Real(1));
    return (p - (a + t * ab)).norm();
}

// Segment-segment distance by ternary search over the first parameter (the distance from a
// moving point to a segment is convex in the parameter): an independent reference for RTCD 5.1.9.
Real segmentSegmentReference(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2,
                             Vec3* on1 = nullptr) {
    Real lo = 0;
    Real hi = 1;
    for (int i = 0; i < 200; ++i) {
        const Real m1 = lo + (hi - lo) / 3;
        const Real m2 = hi - (hi - lo) / 3;
        if (pointSegmentDistance(p1 + m1 * (q1 - p1), p2, q2) <
            pointSegmentDistance(p1 + m2 * (q1 - p1), p2, q2)) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    if (on1 != nullptr) *on1 = p1 + (lo + hi) / 2 * (q1 - p1);
    return pointSegmentDistance(p1 + (lo + hi) / 2 * (q1 - p1), p2, q2);
}

// Counts colliding outcomes and asserts the random test exercised both answers.
struct Mix {
    int colliding = 0;
    int total = 0;
    void add(const ContactOutput& out) {
        ++total;
        if (isColliding(out.state)) ++colliding;
    }
    void expectBalanced(const char* what) const {
        const double f = double(colliding) / double(total);
        EXPECT_GE(f, 0.3) << what << ": colliding fraction " << f;
        EXPECT_LE(f, 0.7) << what << ": colliding fraction " << f;
    }
};

TEST(Contact, SphereSphereMatchesClosedForm) {
    cdlab_test::Rng rng(1);
    Mix mix;
    for (int n = 0; n < 4000; ++n) {
        const Shape a = Shape::sphere(rng.uniform(0.2, 1.5));
        const Shape b = Shape::sphere(rng.uniform(0.2, 1.5));
        const Pose pa = at(rng.vec(-2, 2), rng.rotation());
        const Pose pb = at(pa.position + rng.vec(-1.6, 1.6), rng.rotation());
        const ContactOutput out = contact(a, pa, b, pb);
        const Vec3 d = pb.position - pa.position;
        const Real scale = std::max(a.radius, b.radius);
        ASSERT_NEAR(out.signed_distance, d.norm() - a.radius - b.radius, 1e-14 * 8 * scale) << n;
        ASSERT_LE((out.normal - d.normalized()).norm(), 1e-12) << n;
        ASSERT_EQ(out.state, collide(a, pa, b, pb).state) << n;
        ASSERT_EQ(out.feature_a.type, FeatureType::Face);
        expectConsistent(a, pa, b, pb, out, 1e-12, "sphere-sphere", n);
        expectMirror(out, contact(b, pb, a, pa), n);
        mix.add(out);
    }
    mix.expectBalanced("sphere-sphere");
}

TEST(Contact, SphereBoxMatchesClosedFormAndGjkEpaAgrees) {
    cdlab_test::Rng rng(2);
    Mix mix;
    int inside = 0;
    for (int n = 0; n < 4000; ++n) {
        const Vec3 h = rng.vec(0.2, 1.5);
        const Shape box = Shape::box(h);
        const Shape hull = boxHull(h);
        const Shape sphere = Shape::sphere(rng.uniform(0.1, 1.0));
        const Pose pb = at(rng.vec(-1, 1), rng.rotation());
        const Pose ps = at(pb.position + rng.vec(-1.8, 1.8), rng.rotation());
        const Vec3 centre = pb.applyInverse(ps.position);
        const Real expected = pointBoxSignedDistance(centre, h) - sphere.radius;
        if (pointBoxSignedDistance(centre, h) < 0) ++inside;
        const Real scale = std::max(h.norm(), sphere.radius);
        for (const Shape* s : {&box, &hull}) {
            const ContactOutput out = contact(sphere, ps, *s, pb);
            ASSERT_NEAR(out.signed_distance, expected, 1e-10 * scale) << n;
            // Normal: from the centre to its closest box point outside (RTCD 5.1.3); inside,
            // minus the normal of the nearest face (the way out is through it).
            const Vec3 clamped = centre.cwiseMax(-h).cwiseMin(h);
            Vec3 expected_normal_local;
            if ((centre - clamped).norm() > 1e-9 * scale) {
                expected_normal_local = (clamped - centre).normalized();
            } else {
                int k = 0;
                (h - centre.cwiseAbs()).minCoeff(&k);
                expected_normal_local = -Vec3::Unit(k) * (centre[k] < 0 ? -1 : 1);
            }
            ASSERT_LE((out.normal - pb.orientation * expected_normal_local).norm(), 1e-9) << n;
            ASSERT_EQ(out.state, collide(sphere, ps, *s, pb).state) << n;
            expectConsistent(sphere, ps, *s, pb, out, 1e-9, "sphere-box", n);
            expectMirror(out, contact(*s, pb, sphere, ps), n);
        }
        mix.add(contact(sphere, ps, box, pb));
    }
    mix.expectBalanced("sphere-box");
    EXPECT_GT(inside, 100);
}

TEST(Contact, AxisAlignedBoxBoxMatchesClosedForm) {
    cdlab_test::Rng rng(3);
    Mix mix;
    for (int n = 0; n < 4000; ++n) {
        const Vec3 ha = rng.vec(0.2, 1.5);
        const Vec3 hb = rng.vec(0.2, 1.5);
        const Pose pa = at(rng.vec(-1, 1));
        const Pose pb = at(pa.position + rng.vec(-2.3, 2.3));
        const Vec3 t = pb.position - pa.position;
        const Vec3 overlap = ha + hb - t.cwiseAbs();  // per-axis overlap of the intervals
        Real expected = 0;
        if ((overlap.array() > 0).all()) {
            expected = -overlap.minCoeff();
        } else {
            expected = (-overlap).cwiseMax(0).norm();
        }
        const Real scale = std::max(ha.norm(), hb.norm());
        const Shape a = Shape::box(ha);
        const Shape b = Shape::box(hb);
        const ContactOutput out = contact(a, pa, b, pb);
        ASSERT_NEAR(out.signed_distance, expected, 1e-10 * scale) << n;
        ASSERT_EQ(out.state, collide(a, pa, b, pb).state) << n;
        if (out.state == ContactState::Penetrating) {
            int k = 0;
            overlap.minCoeff(&k);
            ASSERT_NEAR(std::abs(out.normal[k]), 1, 1e-12) << n;
            ASSERT_GT(out.normal[k] * t[k], 0) << n;
        }
        expectConsistent(a, pa, b, pb, out, 1e-9, "aabb-aabb", n);
        expectMirror(out, contact(b, pb, a, pa), n);
        // The same boxes as hulls take GJK/EPA: the same signed distance.
        const ContactOutput gen = contact(boxHull(ha), pa, boxHull(hb), pb);
        ASSERT_NEAR(gen.signed_distance, expected, 1e-9 * scale) << n;
        mix.add(out);
    }
    mix.expectBalanced("aabb-aabb");
}

TEST(Contact, RotatedBoxBoxSatAgreesWithGjkEpa) {
    cdlab_test::Rng rng(4);
    Mix mix;
    int edge_edge = 0;
    for (int n = 0; n < 3000; ++n) {
        const Vec3 ha = rng.vec(0.2, 1.5);
        const Vec3 hb = rng.vec(0.2, 1.5);
        const Pose pa = at(rng.vec(-1, 1), rng.rotation());
        const Pose pb = at(pa.position + rng.vec(-2.5, 2.5), rng.rotation());
        const Shape a = Shape::box(ha);
        const Shape b = Shape::box(hb);
        const Real scale = std::max(ha.norm(), hb.norm());
        const ContactOutput out = contact(a, pa, b, pb);
        const ContactOutput gen = contact(boxHull(ha), pa, boxHull(hb), pb);
        ASSERT_NEAR(out.signed_distance, gen.signed_distance, 1e-9 * scale) << n;
        ASSERT_EQ(out.state, collide(a, pa, b, pb).state) << n;
        expectConsistent(a, pa, b, pb, out, 1e-9, "box-box", n);
        expectConsistent(boxHull(ha), pa, boxHull(hb), pb, gen, 1e-9, "hullbox-hullbox", n);
        expectMirror(out, contact(b, pb, a, pa), n);
        if (out.state == ContactState::Penetrating && out.feature_a.type == FeatureType::Edge &&
            out.feature_b.type == FeatureType::Edge) {
            ++edge_edge;
        }
        mix.add(out);
    }
    mix.expectBalanced("box-box");
    EXPECT_GT(edge_edge, 10);
}

TEST(Contact, CapsuleCapsuleMatchesReference) {
    cdlab_test::Rng rng(5);
    Mix mix;
    for (int n = 0; n < 3000; ++n) {
        const Shape a = Shape::capsule(rng.uniform(0.1, 0.8), rng.uniform(0.1, 1.5));
        const Shape b = Shape::capsule(rng.uniform(0.1, 0.8), rng.uniform(0.1, 1.5));
        const Pose pa = at(rng.vec(-1, 1), rng.rotation());
        const Pose pb = at(pa.position + rng.vec(-1.4, 1.4), rng.rotation());
        const Vec3 ya = pa.orientation * Vec3::UnitY() * a.half_height;
        const Vec3 yb = pb.orientation * Vec3::UnitY() * b.half_height;
        Vec3 on_a;
        const Real core_distance = segmentSegmentReference(
            pa.position - ya, pa.position + ya, pb.position - yb, pb.position + yb, &on_a);
        const Real expected = core_distance - a.radius - b.radius;
        const Real scale = std::max(a.radius + a.half_height, b.radius + b.half_height);
        const ContactOutput out = contact(a, pa, b, pb);
        ASSERT_NEAR(out.signed_distance, expected, 1e-9 * scale) << n;
        ASSERT_EQ(out.state, collide(a, pa, b, pb).state) << n;
        // Witness on A: its core point pushed out by the radius; the reference core point is
        // found by ternary search (accurate to ~1e-8 of the length where the minimum is flat).
        if (core_distance > 1e-3 * scale) {
            ASSERT_LE((out.point_a - out.normal * a.radius - on_a).norm(), 1e-6 * scale) << n;
        }
        expectConsistent(a, pa, b, pb, out, 1e-9, "capsule-capsule", n);
        expectMirror(out, contact(b, pb, a, pa), n);
        mix.add(out);
    }
    mix.expectBalanced("capsule-capsule");
}

TEST(Contact, SphereCapsuleMatchesClosedFormInBothOrders) {
    cdlab_test::Rng rng(15);
    Mix mix;
    for (int n = 0; n < 3000; ++n) {
        const Shape s = Shape::sphere(rng.uniform(0.1, 1.0));
        const Shape c = Shape::capsule(rng.uniform(0.1, 0.8), rng.uniform(0.1, 1.5));
        const Pose pc = at(rng.vec(-1, 1), rng.rotation());
        const Pose ps = at(pc.position + rng.vec(-1.6, 1.6), rng.rotation());
        // RTCD 5.1.2: the centre against the capsule's segment, minus both radii.
        const Vec3 axis = pc.orientation * Vec3::UnitY() * c.half_height;
        const Real expected =
            pointSegmentDistance(ps.position, pc.position - axis, pc.position + axis) - s.radius -
            c.radius;
        const Real scale = std::max(s.radius, c.radius + c.half_height);
        const ContactOutput sc = contact(s, ps, c, pc);
        const ContactOutput cs = contact(c, pc, s, ps);
        ASSERT_NEAR(sc.signed_distance, expected, 1e-12 * scale) << n;
        ASSERT_EQ(sc.state, collide(s, ps, c, pc).state) << n;
        ASSERT_EQ(cs.state, collide(c, pc, s, ps).state) << n;
        expectConsistent(s, ps, c, pc, sc, 1e-12, "sphere-capsule", n);
        expectConsistent(c, pc, s, ps, cs, 1e-12, "capsule-sphere", n);
        expectMirror(sc, cs, n);
        mix.add(sc);
    }
    mix.expectBalanced("sphere-capsule");
}

// A random convex hull: points on an ellipsoid-ish cloud (fixed seed).
Shape randomHull(cdlab_test::Rng& rng, Real size) {
    std::vector<Vec3> points;
    for (int i = 0; i < 24; ++i) {
        Vec3 p = rng.vec(-1, 1);
        if (p.norm() < 1e-3) p = Vec3::UnitX();
        points.push_back(size * p.normalized().cwiseProduct(Vec3(1, 0.7, 0.5)));
    }
    return Shape::convexHull(hullOf(points));
}

std::vector<Shape> shapeZoo(cdlab_test::Rng& rng) {
    std::vector<Shape> zoo;
    zoo.push_back(Shape::sphere(0.6));
    zoo.push_back(Shape::box(Vec3(0.8, 0.5, 0.3)));
    zoo.push_back(Shape::capsule(0.3, 0.6));
    zoo.push_back(randomHull(rng, 0.9));
    zoo.push_back(Shape::sphere(0.25));
    zoo.push_back(Shape::box(Vec3(0.2, 1.0, 0.6)));
    zoo.push_back(Shape::capsule(0.15, 1.0));
    zoo.push_back(randomHull(rng, 0.5));
    return zoo;
}

// Every convex pair type: state equals collide(), exact mirror, witness invariants; and the
// random poses hit both outcomes for every pair.
TEST(Contact, EveryConvexPairAgreesWithCollideAndMirrors) {
    cdlab_test::Rng rng(6);
    const std::vector<Shape> zoo = shapeZoo(rng);
    for (std::size_t i = 0; i < zoo.size(); ++i) {
        for (std::size_t j = 0; j < zoo.size(); ++j) {
            Mix mix;
            for (int n = 0; n < 400; ++n) {
                const Real reach = boundingRadius(zoo[i]) + boundingRadius(zoo[j]);
                const Pose pa = at(rng.vec(-1, 1), rng.rotation());
                const Vec3 dir = rng.rotation() * Vec3::UnitX();
                const Pose pb =
                    at(pa.position + rng.uniform(0.1, 1.2) * reach * dir, rng.rotation());
                const ContactOutput out = contact(zoo[i], pa, zoo[j], pb);
                const CollideOutput decided = collide(zoo[i], pa, zoo[j], pb);
                ASSERT_EQ(out.state, decided.state) << i << " " << j << " " << n;
                if (out.state == ContactState::Separated) {
                    ASSERT_GE(out.signed_distance, decided.distance) << i << " " << j << " " << n;
                }
                expectConsistent(zoo[i], pa, zoo[j], pb, out, 1e-9, "zoo", n);
                expectMirror(out, contact(zoo[j], pb, zoo[i], pa), n);
                mix.add(out);
            }
            EXPECT_GT(mix.colliding, 40) << i << " " << j;
            EXPECT_LT(mix.colliding, 360) << i << " " << j;
        }
    }
}

// Swapping A and B mirrors the answer for every pair type in all three states: each random pose
// is also moved to exact touching (B by -signed_distance * normal) and pushed 0.2 * size deeper.
// collide() agrees in both orders, and every pair type reaches every state.
TEST(Contact, EveryConvexPairMirrorsWhenSeparatedTouchingAndPenetrating) {
    cdlab_test::Rng rng(16);
    const std::vector<Shape> zoo = shapeZoo(rng);
    for (std::size_t i = 0; i < zoo.size(); ++i) {
        for (std::size_t j = 0; j < zoo.size(); ++j) {
            std::array<int, 3> states{0, 0, 0};
            for (int n = 0; n < 60; ++n) {
                const Real scale = std::max(boundingRadius(zoo[i]), boundingRadius(zoo[j]));
                const Pose pa = at(rng.vec(-1, 1), rng.rotation());
                const Vec3 dir = rng.rotation() * Vec3::UnitX();
                const Real reach = boundingRadius(zoo[i]) + boundingRadius(zoo[j]);
                const Pose start =
                    at(pa.position + rng.uniform(0.2, 1.2) * reach * dir, rng.rotation());
                const ContactOutput first = contact(zoo[i], pa, zoo[j], start);
                ASSERT_NE(first.state, ContactState::Failed) << i << " " << j << " " << n;
                for (const Real push : {Real(-1), Real(0), Real(0.2) * scale}) {
                    Pose pb = start;
                    if (push >= 0) pb.position -= (first.signed_distance + push) * first.normal;
                    const ContactOutput ab = contact(zoo[i], pa, zoo[j], pb);
                    const ContactOutput ba = contact(zoo[j], pb, zoo[i], pa);
                    ASSERT_NE(ab.state, ContactState::Failed) << i << " " << j << " " << n;
                    expectMirror(ab, ba, n);
                    ASSERT_EQ(collide(zoo[i], pa, zoo[j], pb).state, ab.state)
                        << i << " " << j << " " << n;
                    ASSERT_EQ(collide(zoo[j], pb, zoo[i], pa).state, ab.state)
                        << i << " " << j << " " << n;
                    ++states[static_cast<std::size_t>(ab.state)];
                }
            }
            EXPECT_GT(states[0], 5) << i << " " << j;
            EXPECT_GT(states[1], 5) << i << " " << j;
            EXPECT_GT(states[2], 5) << i << " " << j;
        }
    }
}

// The touching convention of contact.h (Touching iff |signed distance| <= kTouchRelativeTolerance
// * scale) holds on both sides of each threshold for the closed forms (sphere-sphere,
// sphere-capsule, capsule-capsule, sphere-box, box-box SAT) and for GJK/EPA (hull-hull,
// hull-sphere, capsule-box, hull-box): poses built at signed distance k * tolerance, k = +-0.5
// (Touching) and +-2 (Separated / Penetrating), in both argument orders; the normal is the face
// normal. Regression: the face-to-face hull pairs got EPA normals 40 to 110 degrees off it (EPA
// from a GJK simplex that did not hold the origin, or GJK's direction through a 1e-14 gap).
TEST(Contact, TouchingConventionOnBothSidesOfTheBand) {
    const Quat q = axisAngle(0.7, Vec3(1, 2, 3));
    const Vec3 origin(0.3, -0.2, 0.1);
    const Vec3 x = q * Vec3::UnitX();  // gap direction, A towards B
    struct Case {
        const char* name;
        Shape a;
        Shape b;
        Real contact_offset;  ///< centre distance along x at signed distance 0
    };
    const std::vector<Case> cases{
        {"sphere-sphere", Shape::sphere(0.5), Shape::sphere(0.75), 1.25},
        {"sphere-capsule", Shape::sphere(0.5), Shape::capsule(0.25, 0.5), 0.75},
        {"capsule-capsule", Shape::capsule(0.25, 0.5), Shape::capsule(0.375, 0.75), 0.625},
        {"sphere-box", Shape::sphere(0.5), Shape::box(Vec3(0.25, 0.5, 0.75)), 0.75},
        {"box-box", Shape::box(Vec3(0.5, 0.5, 0.5)), Shape::box(Vec3(0.25, 0.75, 0.5)), 0.75},
        {"hull-hull", boxHull(Vec3(0.5, 0.5, 0.5)), boxHull(Vec3(0.25, 0.75, 0.5)), 0.75},
        {"hull-sphere", boxHull(Vec3(0.5, 0.5, 0.5)), Shape::sphere(0.25), 0.75},
        {"capsule-box", Shape::capsule(0.25, 0.5), Shape::box(Vec3(0.25, 0.75, 0.5)), 0.5},
        {"hull-box", boxHull(Vec3(0.5, 0.5, 0.5)), Shape::box(Vec3(0.25, 0.75, 0.5)), 0.75},
    };
    for (const Case& c : cases) {
        const Real scale = std::max(boundingRadius(c.a), boundingRadius(c.b));
        const Real tol = collision::kTouchRelativeTolerance * scale;
        for (const Real k : {Real(-2), Real(-0.5), Real(0), Real(0.5), Real(2)}) {
            const ContactState expected = k > 1    ? ContactState::Separated
                                          : k < -1 ? ContactState::Penetrating
                                                   : ContactState::Touching;
            const Pose pa = at(origin, q);
            const Pose pb = at(origin + (c.contact_offset + k * tol) * x, q);
            const ContactOutput ab = contact(c.a, pa, c.b, pb);
            const ContactOutput ba = contact(c.b, pb, c.a, pa);
            EXPECT_EQ(ab.state, expected) << c.name << " k=" << k;
            EXPECT_EQ(ba.state, expected) << c.name << " k=" << k;
            EXPECT_EQ(collide(c.a, pa, c.b, pb).state, expected) << c.name << " k=" << k;
            EXPECT_EQ(collide(c.b, pb, c.a, pa).state, expected) << c.name << " k=" << k;
            // The signed distance is in the state's range and within rounding of k * tol.
            EXPECT_NEAR(ab.signed_distance, k * tol, 0.25 * tol) << c.name << " k=" << k;
            EXPECT_LE((ab.normal - x).norm(), 1e-9) << c.name << " k=" << k;
        }
    }
}

// Near-touching poses: B is moved along a random direction to within a few tolerances of
// contact, where rounding decides; the state must still be collide()'s, and a Separated signed
// distance never below collide()'s distance.
TEST(Contact, NearTouchingStateAgreesWithCollide) {
    cdlab_test::Rng rng(7);
    const std::vector<Shape> zoo = shapeZoo(rng);
    int touching = 0;
    for (std::size_t i = 0; i < zoo.size(); ++i) {
        for (std::size_t j = 0; j < zoo.size(); ++j) {
            for (int n = 0; n < 100; ++n) {
                const Pose pa = at(rng.vec(-1, 1), rng.rotation());
                Pose pb = at(pa.position + rng.vec(-1.4, 1.4), rng.rotation());
                const ContactOutput first = contact(zoo[i], pa, zoo[j], pb);
                if (first.state == ContactState::Failed) continue;
                // Move B so the signed distance becomes a few tolerances around zero.
                const Real scale = std::max(boundingRadius(zoo[i]), boundingRadius(zoo[j]));
                const Real tol = collision::kTouchRelativeTolerance * scale;
                pb.position -= (first.signed_distance - rng.uniform(-3, 3) * tol) * first.normal;
                const ContactOutput out = contact(zoo[i], pa, zoo[j], pb);
                const CollideOutput decided = collide(zoo[i], pa, zoo[j], pb);
                ASSERT_EQ(out.state, decided.state) << i << " " << j << " " << n;
                if (out.state == ContactState::Separated) {
                    ASSERT_GE(out.signed_distance, decided.distance) << i << " " << j << " " << n;
                }
                ASSERT_TRUE(out.normal.allFinite());
                expectMirror(out, contact(zoo[j], pb, zoo[i], pa), n);
                if (out.state == ContactState::Touching) ++touching;
            }
        }
    }
    EXPECT_GT(touching, 500);
}

TEST(Contact, SphereSphereExactTouchingAndCoincidentCentres) {
    const Shape a = Shape::sphere(1);
    const Shape b = Shape::sphere(0.5);
    const ContactOutput touch = contact(a, at(Vec3(0, 0, 0)), b, at(Vec3(0, 1.5, 0)));
    EXPECT_EQ(touch.state, ContactState::Touching);
    EXPECT_EQ(touch.signed_distance, 0);
    EXPECT_EQ(touch.normal, Vec3(0, 1, 0));
    EXPECT_EQ(touch.manifold_size, 1);
    EXPECT_EQ(touch.manifold[0].depth, 0);
    // Coincident centres: no direction; the documented normal is the canonically first shape's
    // local +x (here A: same type, lower key), depth the sum of the radii.
    const Pose pa = at(Vec3(1, 2, 3), axisAngle(0.5, Vec3(0, 0, 1)));
    const Pose pb = at(Vec3(1, 2, 3), axisAngle(1.0, Vec3(1, 1, 0)));
    const ContactOutput out = contact(a, pa, b, pb);
    EXPECT_EQ(out.state, ContactState::Penetrating);
    EXPECT_DOUBLE_EQ(out.signed_distance, -1.5);
    ASSERT_TRUE(out.normal.allFinite());
    EXPECT_NEAR(out.normal.norm(), 1, 1e-15);
    expectMirror(out, contact(b, pb, a, pa), 0);
    expectConsistent(a, pa, b, pb, out, 1e-12, "coincident", 0);
    // Deterministic: the same call twice gives bit-identical output.
    const ContactOutput again = contact(a, pa, b, pb);
    EXPECT_EQ(again.normal, out.normal);
    EXPECT_EQ(again.point_a, out.point_a);
}

TEST(Contact, DegenerateConfigurationsGiveFiniteNormals) {
    // Sphere centre on a capsule axis, crossing capsule axes, parallel coincident capsules,
    // sphere centre at a box centre, coincident boxes and hulls.
    cdlab_test::Rng rng(8);
    const Shape hull = randomHull(rng, 0.7);
    struct Case {
        Shape a;
        Pose pa;
        Shape b;
        Pose pb;
    };
    const std::vector<Case> cases{
        {Shape::sphere(0.3), at(Vec3(0, 0.2, 0)), Shape::capsule(0.2, 1), at(Vec3::Zero())},
        {Shape::capsule(0.2, 1), at(Vec3::Zero()), Shape::capsule(0.3, 1),
         at(Vec3::Zero(), axisAngle(M_PI / 2, Vec3::UnitZ()))},
        {Shape::capsule(0.2, 1), at(Vec3(1, 1, 1)), Shape::capsule(0.3, 0.5), at(Vec3(1, 1, 1))},
        {Shape::sphere(0.3), at(Vec3(5, 5, 5)), Shape::box(Vec3(1, 1, 1)), at(Vec3(5, 5, 5))},
        {Shape::box(Vec3(1, 2, 3)), at(Vec3::Zero()), Shape::box(Vec3(1, 2, 3)), at(Vec3::Zero())},
        {hull, at(Vec3::Zero()), hull, at(Vec3::Zero())},
        {Shape::sphere(0.3), at(Vec3::Zero()), hull, at(Vec3::Zero())},
        {Shape::capsule(0.3, 0.2), at(Vec3::Zero()), Shape::box(Vec3(1, 1, 1)), at(Vec3::Zero())},
    };
    for (std::size_t n = 0; n < cases.size(); ++n) {
        const Case& c = cases[n];
        const ContactOutput out = contact(c.a, c.pa, c.b, c.pb);
        ASSERT_EQ(out.state, ContactState::Penetrating) << n;
        ASSERT_EQ(out.state, collide(c.a, c.pa, c.b, c.pb).state) << n;
        expectConsistent(c.a, c.pa, c.b, c.pb, out, 1e-9, "degenerate", static_cast<int>(n));
        // Identical inputs (same shape, same pose) make contact(a, b) and contact(b, a) the
        // same call: no mirror is possible there.
        const bool identical = c.a.type == c.b.type && c.a.hull == c.b.hull &&
                               c.a.half_extents == c.b.half_extents &&
                               c.pa.position == c.pb.position;
        if (!identical) expectMirror(out, contact(c.b, c.pb, c.a, c.pa), static_cast<int>(n));
    }
    // Crossing capsule axes: depth is the sum of the radii along the common perpendicular.
    const ContactOutput cross = contact(cases[1].a, cases[1].pa, cases[1].b, cases[1].pb);
    EXPECT_NEAR(cross.signed_distance, -0.5, 1e-15);
    EXPECT_NEAR(std::abs(cross.normal.z()), 1, 1e-15);
    // Sphere at the centre of a unit cube: leaves through a face, depth 1 + r.
    const ContactOutput centred = contact(cases[3].a, cases[3].pa, cases[3].b, cases[3].pb);
    EXPECT_NEAR(centred.signed_distance, -1.3, 1e-15);
    EXPECT_EQ(centred.feature_b.type, FeatureType::Face);
}

TEST(Contact, NonFiniteInputFails) {
    const Shape a = Shape::sphere(1);
    const ContactOutput out =
        contact(a, at(Vec3(std::nan(""), 0, 0)), Shape::box(Vec3(1, 1, 1)), at(Vec3::Zero()));
    EXPECT_EQ(out.state, ContactState::Failed);
    EXPECT_EQ(out.normal, Vec3::Zero());
    EXPECT_EQ(out.signed_distance, 0);
}

// Box witness features: a sphere over a vertex, an edge and a face of a box, outside and inside.
TEST(Contact, BoxFeaturesForVertexEdgeFace) {
    const Shape box = Shape::box(Vec3(1, 2, 3));
    const Shape sphere = Shape::sphere(0.5);
    const Pose pb = at(Vec3(10, -20, 30), axisAngle(0.3, Vec3(1, 2, 3)));
    auto sphereAt = [&](const Vec3& local) { return at(pb.apply(local)); };
    // Vertex +x -y +z = bits 0 and 2 -> index 5.
    ContactOutput out = contact(box, pb, sphere, sphereAt(Vec3(1.3, -2.3, 3.3)));
    EXPECT_EQ(out.feature_a.type, FeatureType::Vertex);
    EXPECT_EQ(out.feature_a.index, 5);
    EXPECT_EQ(out.feature_b.type, FeatureType::Face);
    // Edge along y at x = -1, z = +3: 4 * 1 + bit_x(0) + 2 * bit_z(1) = 6.
    out = contact(box, pb, sphere, sphereAt(Vec3(-1.3, 0.5, 3.3)));
    EXPECT_EQ(out.feature_a.type, FeatureType::Edge);
    EXPECT_EQ(out.feature_a.index, 6);
    // Face -y (index 2), touching from outside, and the same face from just inside.
    out = contact(box, pb, sphere, sphereAt(Vec3(0.2, -2.4, 1)));
    EXPECT_EQ(out.feature_a.type, FeatureType::Face);
    EXPECT_EQ(out.feature_a.index, 2);
    EXPECT_EQ(out.state, ContactState::Penetrating);
    out = contact(box, pb, sphere, sphereAt(Vec3(0.2, -1.9, 1)));
    EXPECT_EQ(out.feature_a.type, FeatureType::Face);
    EXPECT_EQ(out.feature_a.index, 2);
    // Box-box: B's vertex pushed into A's +z face; crossed edges.
    const Shape cube = Shape::box(Vec3(1, 1, 1));
    const Pose corner_down = at(Vec3(0.1, -0.2, 1 + std::sqrt(Real(3)) - 0.05),
                                Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), Vec3(0, 0, 1)));
    out = contact(cube, at(Vec3::Zero()), cube, corner_down);
    EXPECT_EQ(out.state, ContactState::Penetrating);
    EXPECT_NEAR(out.signed_distance, -0.05, 1e-12);
    EXPECT_EQ(out.feature_a.type, FeatureType::Face);
    EXPECT_EQ(out.feature_a.index, 5);
    EXPECT_EQ(out.feature_b.type, FeatureType::Vertex);
    EXPECT_EQ(out.manifold_size, 1);
    // Edges: A's top edge along x (y = z = +1, edge index 4*0 + 1 + 2 = 3) against B's edge along
    // B's local z at x = y = -h (index 4*2 + 0 + 0 = 8), turned to run along (0, -1, 1) with the
    // edge's outward bisector pointing down (0, -1, -1): they cross at depth 0.01 along (0,1,1).
    const Real r2 = std::sqrt(Real(2));
    const Vec3 u_img = Vec3(0, -1, -1) / r2;  // image of local (-1, -1, 0) / sqrt 2
    const Vec3 z_img = Vec3(0, -1, 1) / r2;
    const Vec3 v_img = z_img.cross(u_img);  // image of local (1, -1, 0) / sqrt 2
    collision::Mat3 rot;
    rot.col(0) = (v_img - u_img) / r2;
    rot.col(1) = -(u_img + v_img) / r2;
    rot.col(2) = z_img;
    const Real h = 0.5;
    const Real pen = 0.01;
    const Shape small = Shape::box(Vec3(h, h, h));
    const Pose crossed =
        at(Vec3(0, 1, 1) + h * Vec3(0, 1, 1) - pen * Vec3(0, 1, 1) / r2, Quat(rot));
    out = contact(cube, at(Vec3::Zero()), small, crossed);
    ASSERT_EQ(out.state, ContactState::Penetrating);
    EXPECT_NEAR(out.signed_distance, -pen, 1e-12);
    EXPECT_LE((out.normal - Vec3(0, 1, 1) / r2).norm(), 1e-12);
    EXPECT_EQ(out.feature_a.type, FeatureType::Edge);
    EXPECT_EQ(out.feature_a.index, 3);
    EXPECT_EQ(out.feature_b.type, FeatureType::Edge);
    EXPECT_EQ(out.feature_b.index, 8);
    EXPECT_EQ(out.manifold_size, 1);
    expectConsistent(cube, at(Vec3::Zero()), small, crossed, out, 1e-12, "crossed", 0);
}

// A box resting flat on a bigger box: four manifold points at the contact depth, at the small
// box's bottom corners; touching exactly gives four points at depth zero.
TEST(Contact, BoxRestingOnBoxGivesFourPoints) {
    const Shape ground = Shape::box(Vec3(5, 5, 0.5));
    const Shape crate = Shape::box(Vec3(0.5, 0.7, 0.4));
    const Quat yaw = axisAngle(0.3, Vec3::UnitZ());
    for (const Real depth : {Real(0), Real(0.01), Real(0.2)}) {
        const Pose pg = at(Vec3(3, -2, 1));
        const Pose pc = at(Vec3(3.2, -1.9, 1 + 0.5 + 0.4 - depth), yaw);
        const ContactOutput out = contact(ground, pg, crate, pc);
        ASSERT_EQ(out.manifold_size, 4) << depth;
        EXPECT_EQ(out.state, depth == 0 ? ContactState::Touching : ContactState::Penetrating);
        EXPECT_NEAR(out.signed_distance, -depth, 1e-12);
        EXPECT_NEAR(out.normal.z(), 1, 1e-12);
        for (int i = 0; i < 4; ++i) {
            const auto& m = out.manifold[static_cast<std::size_t>(i)];
            EXPECT_NEAR(m.depth, depth, 1e-12);
            EXPECT_NEAR(m.point_a.z(), 1.5, 1e-12);
            // At one of the crate's bottom corners.
            const Vec3 local = pc.applyInverse(m.point_b);
            EXPECT_NEAR(local.cwiseAbs().x(), 0.5, 1e-12);
            EXPECT_NEAR(local.cwiseAbs().y(), 0.7, 1e-12);
            EXPECT_NEAR(local.z(), -0.4, 1e-12);
        }
        expectConsistent(ground, pg, crate, pc, out, 1e-12, "resting", 0);
        expectMirror(out, contact(crate, pc, ground, pg), 0);
    }
    // Overhanging the edge: clipped to the ground's face, still four points inside it.
    const Pose pg = at(Vec3::Zero());
    const Pose pc = at(Vec3(4.8, 0, 0.5 + 0.4 - 0.05));
    const ContactOutput out = contact(ground, pg, crate, pc);
    ASSERT_EQ(out.manifold_size, 4);
    for (int i = 0; i < 4; ++i) {
        EXPECT_LE(out.manifold[static_cast<std::size_t>(i)].point_a.x(), 5 + 1e-12);
        EXPECT_NEAR(out.manifold[static_cast<std::size_t>(i)].depth, 0.05, 1e-12);
    }
}

// Metamorphic: translating both shapes by 1e6 and scaling the whole scene by 1e-4 and 1e4
// changes the answer only by rounding relative to the size (and to the offset for points).
TEST(Contact, TranslationAndScaleInvariance) {
    cdlab_test::Rng rng(9);
    for (const Real s : {Real(1e-4), Real(1e4)}) {
        for (const Vec3& offset : {Vec3(0, 0, 0), Vec3(1e6, -1e6, 1e6)}) {
            cdlab_test::Rng shapes(10);
            const std::vector<Shape> zoo = shapeZoo(shapes);
            cdlab_test::Rng shapes_again(10);
            std::vector<Shape> scaled = shapeZoo(shapes_again);
            for (Shape& sh : scaled) {
                sh.radius *= s;
                sh.half_height *= s;
                sh.half_extents *= s;
                if (sh.hull) {
                    ConvexPolytope p = *sh.hull;
                    for (Vec3& v : p.vertices) v *= s;
                    sh.hull = std::make_shared<const ConvexPolytope>(p);
                }
            }
            for (std::size_t i = 0; i < zoo.size(); ++i) {
                for (std::size_t j = 0; j < zoo.size(); ++j) {
                    for (int n = 0; n < 60; ++n) {
                        const Pose pa = at(rng.vec(-1, 1), rng.rotation());
                        const Pose pb = at(pa.position + rng.vec(-1.4, 1.4), rng.rotation());
                        const ContactOutput ref = contact(zoo[i], pa, zoo[j], pb);
                        const Pose qa = at(s * pa.position + offset, pa.orientation);
                        const Pose qb = at(s * pb.position + offset, pb.orientation);
                        const ContactOutput out = contact(scaled[i], qa, scaled[j], qb);
                        // Near the touching band rounding may flip the state; elsewhere equal.
                        const Real scale = std::max(boundingRadius(zoo[i]), boundingRadius(zoo[j]));
                        if (std::abs(ref.signed_distance) > 1e-6 * scale) {
                            ASSERT_EQ(out.state, ref.state) << i << " " << j << " " << n;
                        }
                        // Absolute rounding of coordinates near 1e6 is ~1e6 eps = 2e-10, relative
                        // to a size s: allow 1e-9 relative plus that.
                        const Real tol =
                            1e-9 * scale + 64 * collision::kEpsilon * offset.norm() / s;
                        ASSERT_NEAR(out.signed_distance / s, ref.signed_distance, tol)
                            << i << " " << j << " " << n << " s=" << s;
                        if (std::abs(ref.signed_distance) > 1e-6 * scale &&
                            ref.feature_a.type != FeatureType::Unknown) {
                            // Unique normal except at ties; compare where the depth is clear.
                            ASSERT_LE((out.normal - ref.normal).norm(), 1e-6 + tol)
                                << i << " " << j << " " << n << " s=" << s;
                        }
                        ASSERT_LE(((out.point_a - offset) / s - ref.point_a).norm(),
                                  1e-6 * scale + tol)
                            << i << " " << j << " " << n << " s=" << s;
                        expectConsistent(scaled[i], qa, scaled[j], qb, out, 1e-9, "scaled", n);
                    }
                }
            }
        }
    }
}

// Regression (sliver simplex): a 3.4e-5-thin box B whose corner touches a 4.6 x 0.017 x 2.8 box A.
// GJK's final triangle spanned ~5.6 units but was ~1e-5 wide; its closest point, computed as
// a + v ab + t ac, was off by ~1e-11, enough for support(-v) to return an old vertex, and GJK
// stopped at 6.1e-6 (both contact() and collide() said Separated). The face-region point is now
// the plane projection n (n.a) / |n|^2.
//
//        A (big, flat)          B (thin) touches A with one corner
//   +-----------------+ <.>
TEST(Contact, RegressionSliverSimplexStalledGjkAboveTouching) {
    const Shape a =
        Shape::box(Vec3(0x1.289888f81391dp+2, 0x1.1a613d22f861bp-6, 0x1.684d03ee81fb4p+1));
    const Shape b =
        Shape::box(Vec3(0x1.d83caccb95578p-7, 0x1.1ca5cd56bafcfp-15, 0x1.0e5426ff667f8p-8));
    const Pose pa{Vec3(-0x1.21625414a1bfap+2, 0x1.3eef5f2c539b8p+0, -0x1.32e6fa2d341b6p+2),
                  Quat(-0x1.fbdb13cfccedp-8, -0x1.161b9ab1491e3p-2, -0x1.93ee65958ce87p-2,
                       0x1.c1724dc568b71p-1)};
    const Pose pb{Vec3(-0x1.87e39e9a50fdep-1, 0x1.aa4aaab88fd2p-5, -0x1.27fe0f2f4b715p+1),
                  Quat(0x1.be8b2bd3a1725p-2, -0x1.18190cc6f507bp-1, -0x1.6d12b60b688c9p-1,
                       -0x1.7aceb02ca555ep-5)};
    // Brute force: the deepest corner of B lies on A's surface (|sdf| ~ 1e-15).
    Real deepest = std::numeric_limits<Real>::infinity();
    for (int i = 0; i < 8; ++i) {
        const Vec3& h = b.half_extents;
        const Vec3 corner((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                          (i & 4) ? h.z() : -h.z());
        deepest = std::min(deepest, surfaceDistance(a, pa, pb.apply(corner)));
    }
    ASSERT_NEAR(deepest, 0, 1e-14);
    const ContactOutput out = contact(a, pa, b, pb);
    EXPECT_EQ(out.state, ContactState::Touching);
    EXPECT_NEAR(out.signed_distance, 0, 1e-12);
    EXPECT_EQ(collide(a, pa, b, pb).state, ContactState::Touching);
    expectMirror(out, contact(b, pb, a, pa), 0);
}

// Regression (EPA decision cap): two boxes placed exactly touching (B moved by -distance * normal)
// made collide()'s bounded EPA re-add the same support point until its cap: Failed, and contact()
// inherited it. A repeated support point now ends the decision as Touching.
TEST(Contact, RegressionExactlyTouchingBoxesFailedInEpaDecision) {
    const Shape a =
        Shape::box(Vec3(0x1.31177fc5952e4p-2, 0x1.c2db8553c31c9p-12, 0x1.2d2e1d7452189p-4));
    const Shape b =
        Shape::box(Vec3(0x1.1028f80d6941bp+0, 0x1.29c227091cd84p-6, 0x1.4a23ab3e9f12ep-2));
    const Pose pa{Vec3(-0x1.7fa74c2381be7p-2, 0x1.04ea69cdad63fp-3, -0x1.3a7ade3cbb3cap-1),
                  Quat(-0x1.96d22e3cb2d5ap-1, 0x1.f6b71dc6ce5d9p-5, 0x1.3170643e007cep-1,
                       -0x1.84ad33c03e13bp-4)};
    const Pose pb{Vec3(0x1.91dadb5d2b3d4p-4, 0x1.cb122fb293672p-2, -0x1.c1043e19818e3p-1),
                  Quat(-0x1.c579e67719f9ep-1, -0x1.7447530c6c849p-6, 0x1.398720a3a1339p-2,
                       -0x1.649cc271f3809p-2)};
    EXPECT_EQ(collide(a, pa, b, pb).state, ContactState::Touching);
    EXPECT_EQ(collide(b, pb, a, pa).state, ContactState::Touching);
    const ContactOutput out = contact(a, pa, b, pb);
    EXPECT_EQ(out.state, ContactState::Touching);
    EXPECT_GE(out.manifold_size, 1);
    expectMirror(out, contact(b, pb, a, pa), 0);
}

// Regression (EPA from a separated simplex): a box hull A 8.6e-9 * size away from a box B. GJK
// stopped Separated below kNormalRelative * size, where its direction was not trusted, and EPA
// was started from GJK's final simplex, which does not hold the origin. EPA then "converged" on a
// face the origin lies outside of: depth -8.5e-9 (negative), with that face's witnesses, so
// point_b - point_a was not signed_distance * normal (off by 9e-9 * size, more than the gap).
// A non-positive EPA depth now falls back to GJK's distance and witnesses.
//
//     +-------+   gap 8.6e-9 * size
//     |   A   | <->  <> B (box)       A: an 8-point hull, so the pair takes GJK/EPA
//     +-------+
TEST(Contact, RegressionEpaFromSeparatedSimplexGaveNegativeDepth) {
    const Vec3 ha(0x1.34b0050cfde5p-2, 0x1.81c1670cefe8p-2, 0x1.1bd878665e554p-2);
    const Shape a = boxHull(ha);
    const Shape b =
        Shape::box(Vec3(0x1.ddf9afb7e2caep-3, 0x1.cc6190ffd6d96p-1, 0x1.19ad3ebf020b4p+0));
    const Pose pa{Vec3(-0x1.fc2a30e661f09p-1, 0x1.75be030e48164p-2, 0x1.12a05f29b35ep-1),
                  Quat(-0x1.e72fe1f4f53e5p-2, -0x1.a0bbb00d97b9ap-1, -0x1.2038211725a73p-4,
                       -0x1.4db776233406ep-2)};
    const Pose pb{Vec3(0x1.fd6abc6cdfed8p-4, 0x1.c73e4c1a02124p-2, 0x1.39e22085acbd6p+0),
                  Quat(0x1.fdd9c67251902p-5, 0x1.a2f2d49e31db5p-1, -0x1.d0fe0504664cap-2,
                       0x1.63480fd5a33d4p-2)};
    const Real scale = std::max(boundingRadius(a), boundingRadius(b));
    const ContactOutput out = contact(a, pa, b, pb);
    ASSERT_EQ(out.state, ContactState::Separated);
    EXPECT_GT(out.signed_distance, 1e-9 * scale);
    EXPECT_LT(out.signed_distance, 1e-8 * scale);
    EXPECT_LE((out.point_b - out.point_a - out.signed_distance * out.normal).norm(), 1e-12 * scale);
    // Independent of GJK/EPA: the largest separation over 20000 sampled directions and every SAT
    // axis is a lower bound on the distance (1.2319e-8 here; GJK's 1.2360e-8 is an upper one).
    const Real lower = -collision::minimumOverlapReference(a, pa, b, pb, 20000).overlap;
    EXPECT_GE(out.signed_distance, lower - 1e-12 * scale);
    EXPECT_LE(out.signed_distance, lower + 1e-2 * out.signed_distance);
    expectConsistent(a, pa, b, pb, out, 1e-12, "epa-separated", 0);
    expectMirror(out, contact(b, pb, a, pa), 0);
}

// Thin and lopsided shapes placed exactly touching (moved by -distance * normal from a random
// pose) or with coincident origins: contact() never fails, agrees with collide() and mirrors.
TEST(Contact, ExtremeAspectRatiosTouchingAndCoincident) {
    cdlab_test::Rng rng(12);
    int touching = 0;
    for (int n = 0; n < 20000; ++n) {
        auto make = [&](int kind) {
            const Real size = std::pow(Real(10), rng.uniform(-2, 1));
            const Real thin = std::pow(Real(10), rng.uniform(-3, 0));
            if (kind == 0) return Shape::sphere(size);
            if (kind == 1) return Shape::box(Vec3(size, size * thin, size * rng.uniform(0.01, 1)));
            if (kind == 2) return Shape::capsule(size * thin, size * rng.uniform(0, 2));
            std::vector<Vec3> points;
            for (int i = 0; i < 12; ++i)
                points.push_back(size * rng.vec(-1, 1).cwiseProduct(Vec3(1, thin, 1)));
            return Shape::convexHull(hullOf(points));
        };
        const Shape a = make(rng.integer(0, 3));
        const Shape b = make(rng.integer(0, 3));
        const Real reach = boundingRadius(a) + boundingRadius(b);
        const Pose pa = at(rng.vec(-1, 1) * reach, rng.rotation());
        Pose pb = at(pa.position + rng.uniform(0, 1.1) * reach * (rng.rotation() * Vec3::UnitX()),
                     rng.rotation());
        if (n % 2 == 0) {
            const ContactOutput first = contact(a, pa, b, pb);
            ASSERT_NE(first.state, ContactState::Failed) << n;
            pb.position -= first.signed_distance * first.normal;
        } else if (n % 5 == 1) {
            pb.position = pa.position;
        }
        const ContactOutput out = contact(a, pa, b, pb);
        ASSERT_NE(out.state, ContactState::Failed) << n;
        ASSERT_EQ(out.state, collide(a, pa, b, pb).state) << n;
        const Real scale = std::max(boundingRadius(a), boundingRadius(b));
        ASSERT_LE((out.point_b - out.point_a - out.signed_distance * out.normal).norm(),
                  1e-8 * scale)
            << n;
        // Manifold points: the witness identity with their own depth, never deeper than the
        // contact (thin reference shapes once gave points beyond their far side).
        for (int i = 0; i < out.manifold_size; ++i) {
            const auto& m = out.manifold[static_cast<std::size_t>(i)];
            ASSERT_LE((m.point_b - m.point_a + m.depth * out.normal).norm(), 1e-8 * scale) << n;
            ASSERT_LE(m.depth, -out.signed_distance + 1e-8 * scale) << n;
        }
        if (pb.position != pa.position || a.type != b.type) {
            expectMirror(out, contact(b, pb, a, pa), n);
        }
        if (out.state == ContactState::Touching) ++touching;
    }
    EXPECT_GT(touching, 5000);
}

// Hull face contacts get a clipped manifold like boxes: a box-shaped hull resting on a slab hull,
// and a hexagonal prism (6-vertex face) resting on it, reduced to 4 points at the right depth.
TEST(Contact, HullRestingOnHullGivesClippedManifold) {
    const Shape ground = boxHull(Vec3(4, 4, 0.5));
    const Shape crate = boxHull(Vec3(0.5, 0.7, 0.4));
    std::vector<Vec3> prism_points;
    for (int i = 0; i < 6; ++i) {
        const Real t = Real(i) * Real(M_PI) / 3;
        prism_points.emplace_back(0.6 * std::cos(t), 0.6 * std::sin(t), -0.3);
        prism_points.emplace_back(0.6 * std::cos(t), 0.6 * std::sin(t), 0.3);
    }
    const Shape prism = Shape::convexHull(hullOf(prism_points));
    const Pose pg = at(Vec3(1, 2, -3));
    const Real depth = 0.02;
    struct Case {
        const Shape* shape;
        Real half_height;
        int expected_points;
    };
    for (const Case& c : {Case{&crate, 0.4, 4}, Case{&prism, 0.3, 4}}) {
        const Pose pc =
            at(Vec3(1.3, 1.8, -3 + 0.5 + c.half_height - depth), axisAngle(0.4, Vec3::UnitZ()));
        for (const bool swapped : {false, true}) {
            const ContactOutput out =
                swapped ? contact(*c.shape, pc, ground, pg) : contact(ground, pg, *c.shape, pc);
            ASSERT_EQ(out.state, ContactState::Penetrating);
            EXPECT_NEAR(out.signed_distance, -depth, 1e-9);
            EXPECT_NEAR(std::abs(out.normal.z()), 1, 1e-12);
            ASSERT_EQ(out.manifold_size, c.expected_points) << swapped;
            for (int i = 0; i < out.manifold_size; ++i) {
                const auto& m = out.manifold[static_cast<std::size_t>(i)];
                EXPECT_NEAR(m.depth, depth, 1e-9);
                const Vec3& on_ground = swapped ? m.point_b : m.point_a;
                EXPECT_NEAR(on_ground.z(), -2.5, 1e-9);
            }
            if (swapped) {
                expectConsistent(*c.shape, pc, ground, pg, out, 1e-9, "hull-rest", 0);
            } else {
                expectConsistent(ground, pg, *c.shape, pc, out, 1e-9, "hull-rest", 0);
            }
        }
        // The manifold spans the face: the chosen points are far apart (not 4 near one corner).
        const ContactOutput out = contact(ground, pg, *c.shape, pc);
        Real spread = 0;
        for (int i = 0; i < out.manifold_size; ++i) {
            for (int j = 0; j < out.manifold_size; ++j) {
                spread = std::max(spread, (out.manifold[static_cast<std::size_t>(i)].point_b -
                                           out.manifold[static_cast<std::size_t>(j)].point_b)
                                              .norm());
            }
        }
        EXPECT_GT(spread, 1.0);
    }
    // Box (SAT path) on a hull ground: GJK/EPA normal, clipped manifold of 4.
    const Pose pc = at(Vec3(0.5, 2, -3 + 0.5 + 0.4 - depth), axisAngle(0.2, Vec3::UnitZ()));
    const ContactOutput mixed = contact(ground, pg, Shape::box(Vec3(0.5, 0.7, 0.4)), pc);
    EXPECT_EQ(mixed.manifold_size, 4)
        << std::setprecision(17) << mixed.normal.transpose() << " sd " << mixed.signed_distance;
    EXPECT_NEAR(mixed.signed_distance, -depth, 1e-9);
}

// Hull witness features on a tetrahedron (no coplanar faces): a sphere over a vertex, over an
// edge and over a face interior gets that vertex index, the edge as face * 3 + edge of a face
// holding both endpoints, and a face whose plane holds the witness.
TEST(Contact, HullFeaturesForVertexEdgeFace) {
    const std::vector<Vec3> corners{Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1),
                                    Vec3(-1, -1, 1)};
    const Shape tet = Shape::convexHull(hullOf(corners));
    const ConvexPolytope& hull = *tet.hull;
    const Shape sphere = Shape::sphere(0.1);
    const Pose pt = at(Vec3(100, 200, -300), axisAngle(0.7, Vec3(1, -1, 2)));
    // Vertex: straight out beyond corner 0.
    int v0 = -1;
    for (std::size_t i = 0; i < hull.vertices.size(); ++i) {
        if ((hull.vertices[i] - corners[0]).norm() < 1e-12) v0 = static_cast<int>(i);
    }
    ASSERT_GE(v0, 0);
    ContactOutput out = contact(tet, pt, sphere, at(pt.apply(corners[0] * 1.2)));
    EXPECT_EQ(out.feature_a.type, FeatureType::Vertex);
    EXPECT_EQ(out.feature_a.index, v0);
    // Edge: beyond the midpoint of corners 0 and 1, along the outward bisector.
    const Vec3 mid = (corners[0] + corners[1]) / 2;
    out = contact(tet, pt, sphere, at(pt.apply(mid + 0.12 * mid.normalized())));
    ASSERT_EQ(out.feature_a.type, FeatureType::Edge);
    const auto& face = hull.faces[static_cast<std::size_t>(out.feature_a.index / 3)];
    const int e = out.feature_a.index % 3;
    const Vec3 s = hull.vertices[static_cast<std::size_t>(face[static_cast<std::size_t>(e)])];
    const Vec3 t =
        hull.vertices[static_cast<std::size_t>(face[static_cast<std::size_t>((e + 1) % 3)])];
    EXPECT_NEAR((s - t).norm(), (corners[0] - corners[1]).norm(), 1e-12);
    EXPECT_NEAR((s + t - corners[0] - corners[1]).norm(), 0, 1e-12);
    // Face: beyond the centroid of the face opposite corner 3, inside and outside.
    const Vec3 centroid = (corners[0] + corners[1] + corners[2]) / 3;
    for (const Real lift : {Real(0.15), Real(0.05)}) {
        out = contact(tet, pt, sphere, at(pt.apply(centroid + lift * centroid.normalized())));
        ASSERT_EQ(out.feature_a.type, FeatureType::Face) << lift;
        const auto& f = hull.faces[static_cast<std::size_t>(out.feature_a.index)];
        for (int k = 0; k < 3; ++k) {
            const Vec3& c = hull.vertices[static_cast<std::size_t>(f[static_cast<std::size_t>(k)])];
            EXPECT_GT((c - corners[3]).norm(), 1) << lift;  // corner 3 is not on that face
        }
    }
}

// A mesh is its convex hull for contact(): the same answer as the hull shape, mirrored when
// swapped, for a concave (L-shaped) mesh whose hull differs from its surface.
TEST(Contact, MeshIsItsConvexHull) {
    auto mesh = std::make_shared<collision::TriangleMesh>();
    // An L-shaped prism: 6 profile corners at z = -0.5 and z = +0.5 (triangles only matter for
    // collide(); contact() reads the hull).
    const std::array<std::array<Real, 2>, 6> profile{
        {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}};
    for (const Real z : {Real(-0.5), Real(0.5)}) {
        for (const auto& p : profile) mesh->vertices.emplace_back(p[0] - 1, p[1] - 1, z);
    }
    mesh->triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}};
    const auto hull = hullOf(mesh->vertices);
    const Shape as_mesh = Shape::triangleMesh(mesh, hull);
    const Shape as_hull = Shape::convexHull(hull);
    cdlab_test::Rng rng(13);
    const Shape other = Shape::box(Vec3(0.4, 0.3, 0.2));
    int colliding = 0;
    for (int n = 0; n < 300; ++n) {
        const Pose pm = at(rng.vec(-1, 1), rng.rotation());
        const Pose po = at(pm.position + rng.vec(-2, 2), rng.rotation());
        const ContactOutput m = contact(as_mesh, pm, other, po);
        const ContactOutput h = contact(as_hull, pm, other, po);
        ASSERT_EQ(m.state, h.state) << n;
        ASSERT_EQ(m.signed_distance, h.signed_distance) << n;
        ASSERT_EQ(m.normal, h.normal) << n;
        ASSERT_EQ(m.point_a, h.point_a) << n;
        ASSERT_EQ(m.feature_a.index, h.feature_a.index) << n;
        expectMirror(m, contact(other, po, as_mesh, pm), n);
        expectConsistent(as_hull, pm, other, po, m, 1e-9, "mesh", n);
        if (isColliding(m.state)) ++colliding;
    }
    EXPECT_GT(colliding, 30);
    EXPECT_LT(colliding, 270);
}

// Finely tessellated hulls (2000 points on a sphere) make EPA work hardest: every query stays
// within the iteration caps, none fails, and the state is collide()'s.
TEST(Contact, FineHullsStayWithinTheIterationCaps) {
    cdlab_test::Rng rng(14);
    std::vector<Vec3> points;
    for (int i = 0; i < 2000; ++i) points.push_back(rng.vec(-1, 1).normalized());
    const Shape ball = Shape::convexHull(hullOf(points));
    const Shape box = Shape::box(Vec3(0.5, 0.4, 0.3));
    int penetrating = 0;
    for (int n = 0; n < 150; ++n) {
        const Shape& other = n % 2 == 0 ? ball : box;
        const Pose pa = at(rng.vec(-1, 1), rng.rotation());
        const Pose pb = at(pa.position + rng.vec(-1, 1) * 1.2, rng.rotation());
        const ContactOutput out = contact(ball, pa, other, pb);
        ASSERT_NE(out.state, ContactState::Failed) << n;
        ASSERT_EQ(out.state, collide(ball, pa, other, pb).state) << n;
        ASSERT_LE(out.iterations, collision::kGjkMaxIterations + collision::kEpaMaxIterations);
        expectConsistent(ball, pa, other, pb, out, 1e-9, "fine hull", n);
        if (out.state == ContactState::Penetrating) ++penetrating;
    }
    EXPECT_GT(penetrating, 50);
}

}  // namespace
