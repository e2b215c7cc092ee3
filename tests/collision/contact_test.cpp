// tests/collision/contact_test.cpp -- contact(): depth/distance, normal, witnesses, features and
// manifold against closed forms (sphere-sphere, sphere-box, axis-aligned box-box,
// capsule-capsule) on random pairs that collide 30-70 % of the time; GJK/EPA (boxes and spheres
// given as hulls) against the same closed forms and against box-box SAT; mirror symmetry,
// agreement with collide(), exact touching, metamorphic translation and scaling.
#include "collision/contact.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "collision/convex_hull.h"
#include "collision/narrow_phase.h"
#include "test_random.h"

namespace {

using collision::collide;
using collision::contact;
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

[[maybe_unused]] Quat axisAngle(Real angle, const Vec3& axis) {
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

Real boundingRadius(const Shape& s) {
    switch (s.type) {
        case ShapeType::Sphere:
            return s.radius;
        case ShapeType::Box:
            return s.half_extents.norm();
        case ShapeType::Capsule:
            return s.half_height + s.radius;
        default: {
            Real r = 0;
            for (const Vec3& v : s.hull->vertices) r = std::max(r, v.norm());
            return r;
        }
    }
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
Real segmentSegmentReference(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2) {
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
        const Real expected = segmentSegmentReference(pa.position - ya, pa.position + ya,
                                                      pb.position - yb, pb.position + yb) -
                              a.radius - b.radius;
        const Real scale = std::max(a.radius + a.half_height, b.radius + b.half_height);
        const ContactOutput out = contact(a, pa, b, pb);
        ASSERT_NEAR(out.signed_distance, expected, 1e-9 * scale) << n;
        ASSERT_EQ(out.state, collide(a, pa, b, pb).state) << n;
        expectConsistent(a, pa, b, pb, out, 1e-9, "capsule-capsule", n);
        expectMirror(out, contact(b, pb, a, pa), n);
        mix.add(out);
    }
    mix.expectBalanced("capsule-capsule");
}

}  // namespace
