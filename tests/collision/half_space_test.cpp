// tests/collision/half_space_test.cpp -- contact() of a half-space with each convex shape
// (sphere, box, capsule, hull): signed distance, state, witnesses and normal against a brute
// force over the shape's vertex set (box, hull) or cap centres (capsule) and dense samples of
// its surface, on random poses that are separated, penetrating and exactly touching; features
// in closed-form cases; swapped order mirrors; translation by 1e6 and scales 1e-4..1e4.
#include "collision/narrowphase/half_space.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <vector>

#include "collision/geometry/convex_hull.h"
#include "collision/narrowphase/narrow_phase.h"
#include "test_random.h"
#include "test_shapes.h"

namespace {

using cdlab_test::boundingRadius;

using collision::contact;
using collision::ContactOutput;
using collision::ContactState;
using collision::ConvexPolytope;
using collision::FeatureType;
using collision::HalfSpace;
using collision::kEpsilon;
using collision::Pose;
using collision::Quat;
using collision::Real;
using collision::Shape;
using collision::ShapeType;
using collision::Vec3;

std::shared_ptr<const ConvexPolytope> hullOf(const std::vector<Vec3>& points) {
    const auto out = collision::computeConvexHull(points);
    EXPECT_TRUE(out.ok) << out.error;
    return std::make_shared<const ConvexPolytope>(out.hull);
}

// The four shapes at unit size times `s`; the hull is an irregular 12-point polytope.
std::vector<Shape> shapesAt(Real s) {
    cdlab_test::Rng rng(11);
    std::vector<Vec3> pts;
    for (int i = 0; i < 12; ++i) pts.push_back(rng.vec(-1, 1).cwiseProduct(Vec3(1, 0.6, 0.8)) * s);
    return {Shape::sphere(Real(0.7) * s), Shape::box(Vec3(0.5, 0.3, 0.8) * s),
            Shape::capsule(Real(0.3) * s, Real(0.6) * s), Shape::convexHull(hullOf(pts))};
}

// The brute-force reference: min over the shape's vertex set (box corners, hull vertices) of
// n.x - d, or over its core points (sphere centre, the capsule's two cap centres) minus the
// radius. Independent of the support-point code.
Real referenceSignedDistance(const Shape& b, const Pose& pose, const HalfSpace& h) {
    std::vector<Vec3> core;
    Real radius = 0;
    switch (b.type) {
        case ShapeType::Sphere:
            core.push_back(Vec3::Zero());
            radius = b.radius;
            break;
        case ShapeType::Box:
            for (int i = 0; i < 8; ++i) {
                core.push_back(b.half_extents.cwiseProduct(
                    Vec3((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1)));
            }
            break;
        case ShapeType::Capsule:
            core = {Vec3(0, -b.half_height, 0), Vec3(0, b.half_height, 0)};
            radius = b.radius;
            break;
        default:
            core = b.hull->vertices;
            break;
    }
    Real best = std::numeric_limits<Real>::infinity();
    for (const Vec3& c : core) best = std::min(best, h.normal.dot(pose.apply(c)) - h.offset);
    return best - radius;
}

// Dense samples of the shape's surface (world frame): every sample's height is >= the answer.
std::vector<Vec3> surfaceSamples(const Shape& b, const Pose& pose) {
    cdlab_test::Rng rng(3);
    std::vector<Vec3> out;
    for (int i = 0; i < 2000; ++i) {
        const Vec3 dir = rng.vec(-1, 1);
        if (!(dir.norm() > Real(1e-3))) continue;
        out.push_back(pose.apply(collision::supportPoint(b, dir)));
    }
    return out;
}

// Is `p` (world) on the shape's surface, to `tol`? Closed-form membership per shape type.
bool onSurface(const Shape& b, const Pose& pose, const Vec3& p, Real tol) {
    const Vec3 y = pose.applyInverse(p);
    switch (b.type) {
        case ShapeType::Sphere:
            return std::abs(y.norm() - b.radius) <= tol;
        case ShapeType::Box: {
            const Vec3 excess = y.cwiseAbs() - b.half_extents;
            return excess.maxCoeff() <= tol && excess.maxCoeff() >= -tol;
        }
        case ShapeType::Capsule: {
            const Real t = std::clamp(y.y(), -b.half_height, b.half_height);
            return std::abs((y - Vec3(0, t, 0)).norm() - b.radius) <= tol;
        }
        default:
            for (const Vec3& v : b.hull->vertices) {
                if ((v - y).norm() <= tol) return true;
            }
            return false;
    }
}

ContactState expectedState(Real signed_distance, Real scale) {
    const Real tol = collision::kTouchRelativeTolerance * scale;
    if (signed_distance > tol) return ContactState::Separated;
    if (signed_distance >= -tol) return ContactState::Touching;
    return ContactState::Penetrating;
}

// Checks one answer against the brute force.
void expectMatchesReference(const Shape& b, const Pose& pose, const HalfSpace& h,
                            const ContactOutput& c, Real offset_scale, const char* what) {
    const Real scale = boundingRadius(b);
    const Real ref = referenceSignedDistance(b, pose, h);
    // Rounding: of the vertices' world positions and of n.p - d (relative to the offset).
    const Real tol = Real(64) * kEpsilon * (scale + offset_scale);
    ASSERT_NE(c.state, ContactState::Failed) << what;
    EXPECT_NEAR(c.signed_distance, ref, tol) << what;
    if (std::abs(std::abs(ref) - collision::kTouchRelativeTolerance * scale) > tol) {
        EXPECT_EQ(c.state, expectedState(ref, scale)) << what << " ref " << ref;
    }
    EXPECT_EQ(c.normal, h.normal / h.normal.norm()) << what;
    // point_b - point_a = signed distance * normal; point_a on the plane; point_b on b.
    EXPECT_LE((c.point_b - c.point_a - c.normal * c.signed_distance).norm(), tol) << what;
    EXPECT_NEAR(h.normal.dot(c.point_a), h.offset, tol) << what;
    EXPECT_TRUE(onSurface(b, pose, c.point_b, tol + Real(1e-12) * scale)) << what;
    EXPECT_EQ(c.feature_a.type, FeatureType::Face) << what;
    // No point of the sampled surface lies deeper than the answer.
    Real lowest = std::numeric_limits<Real>::infinity();
    for (const Vec3& p : surfaceSamples(b, pose))
        lowest = std::min(lowest, h.normal.dot(p) - h.offset);
    EXPECT_GE(lowest, c.signed_distance - tol) << what;
    if (c.state != ContactState::Separated) {
        EXPECT_GE(c.manifold_size, 1) << what;
        for (int k = 0; k < c.manifold_size; ++k) {
            const auto& m = c.manifold[static_cast<std::size_t>(k)];
            EXPECT_NEAR(h.normal.dot(m.point_a), h.offset, tol) << what;
            EXPECT_TRUE(onSurface(b, pose, m.point_b, tol + Real(1e-12) * scale)) << what;
            EXPECT_GE(m.depth, 0) << what;
            EXPECT_LE(m.depth, -c.signed_distance + tol) << what;
        }
    } else {
        EXPECT_EQ(c.manifold_size, 0) << what;
    }
}

// The shape-first order is the exact mirror.
void expectMirror(const ContactOutput& hs_first, const ContactOutput& shape_first) {
    EXPECT_EQ(shape_first.state, hs_first.state);
    EXPECT_EQ(shape_first.signed_distance, hs_first.signed_distance);
    EXPECT_EQ(shape_first.normal, -hs_first.normal);
    EXPECT_EQ(shape_first.point_a, hs_first.point_b);
    EXPECT_EQ(shape_first.point_b, hs_first.point_a);
    EXPECT_EQ(shape_first.feature_a.type, hs_first.feature_b.type);
    EXPECT_EQ(shape_first.feature_a.index, hs_first.feature_b.index);
    EXPECT_EQ(shape_first.feature_b.type, hs_first.feature_a.type);
    ASSERT_EQ(shape_first.manifold_size, hs_first.manifold_size);
    for (int k = 0; k < hs_first.manifold_size; ++k) {
        const auto i = static_cast<std::size_t>(k);
        EXPECT_EQ(shape_first.manifold[i].point_a, hs_first.manifold[i].point_b);
        EXPECT_EQ(shape_first.manifold[i].depth, hs_first.manifold[i].depth);
    }
}

TEST(HalfSpace, MatchesBruteForceAtRandomPosesAndScales) {
    cdlab_test::Rng rng(99);
    int counts[4] = {0, 0, 0, 0};
    for (const Real s : {Real(1e-4), Real(1), Real(1e4)}) {
        const std::vector<Shape> shapes = shapesAt(s);
        for (const Real offset : {Real(0), Real(1e6)}) {
            for (int k = 0; k < 200; ++k) {
                const Shape& b = shapes[static_cast<std::size_t>(k % 4)];
                const Pose pose{Vec3::Constant(offset) + rng.vec(-1, 1) * s, rng.rotation()};
                HalfSpace h;
                h.normal = rng.vec(-1, 1).normalized();
                // The plane through a point near the shape: about half the poses penetrate.
                h.offset = h.normal.dot(pose.position) + rng.uniform(-1.5, 1.5) * s;
                if (k % 5 == 0) {
                    // Exactly touching: the plane through the brute force's deepest point.
                    h.offset += referenceSignedDistance(b, pose, h);
                }
                const ContactOutput c = contact(h, b, pose);
                const Real offset_scale = offset + std::abs(h.offset);
                expectMatchesReference(b, pose, h, c, offset_scale, "random pose");
                if (k % 5 == 0 && offset == 0) {
                    EXPECT_EQ(c.state, ContactState::Touching) << "touching, shape " << k % 4;
                }
                expectMirror(c, contact(b, pose, h));
                counts[static_cast<int>(c.state)] += 1;
            }
        }
    }
    // Every state occurs, or the test could not fail.
    EXPECT_GT(counts[0], 200);  // Separated
    EXPECT_GT(counts[1], 100);  // Touching
    EXPECT_EQ(counts[3], 0);    // Failed
    EXPECT_GT(counts[2], 200);  // Penetrating
}

TEST(HalfSpace, TranslationAndScalingChangeTheAnswerOnlyByRounding) {
    cdlab_test::Rng rng(5);
    const std::vector<Shape> unit = shapesAt(1);
    for (int k = 0; k < 200; ++k) {
        const std::size_t which = static_cast<std::size_t>(k % 4);
        const Pose pose{rng.vec(-1, 1), rng.rotation()};
        HalfSpace h{rng.vec(-1, 1).normalized(), 0};
        h.offset = h.normal.dot(pose.position) + rng.uniform(-1.5, 1.5);
        const ContactOutput c = contact(h, unit[which], pose);
        // Translated by 1e6 along a random direction: the plane moves with the shape.
        const Vec3 shift = rng.vec(-1, 1).normalized() * Real(1e6);
        const HalfSpace moved{h.normal, h.offset + h.normal.dot(shift)};
        const ContactOutput t =
            contact(moved, unit[which], Pose{pose.position + shift, pose.orientation});
        EXPECT_NEAR(t.signed_distance, c.signed_distance, Real(64) * kEpsilon * Real(1e6));
        EXPECT_LE((t.point_b - shift - c.point_b).norm(), Real(64) * kEpsilon * Real(1e6));
        for (const Real s : {Real(1e-4), Real(1e4)}) {
            const std::vector<Shape> scaled = shapesAt(s);
            const ContactOutput z = contact(HalfSpace{h.normal, h.offset * s}, scaled[which],
                                            Pose{pose.position * s, pose.orientation});
            EXPECT_NEAR(z.signed_distance, c.signed_distance * s, Real(64) * kEpsilon * s);
            EXPECT_EQ(z.state, c.state);
            EXPECT_EQ(z.feature_b.type, c.feature_b.type);
            EXPECT_EQ(z.feature_b.index, c.feature_b.index);
        }
    }
}

TEST(HalfSpace, ExactTouchingFarFromTheOrigin) {
    // A box resting on the floor y <= 1e6 (exact coordinates: scales are powers of two near
    // 1e-4 and 1e4): Touching with its -y face and a four-point manifold, at every scale.
    for (const Real s : {std::ldexp(Real(1), -13), Real(1), std::ldexp(Real(1), 13)}) {
        const Shape box = Shape::box(Vec3(0.5, 0.25, 2) * s);
        const Pose pose{Vec3(1e6, 1e6 + 0.25 * s, -1e6), Quat::Identity()};
        const ContactOutput c = contact(HalfSpace{Vec3::UnitY(), Real(1e6)}, box, pose);
        EXPECT_EQ(c.state, ContactState::Touching) << s;
        EXPECT_EQ(c.signed_distance, 0) << s;
        EXPECT_EQ(c.feature_b.type, FeatureType::Face);
        EXPECT_EQ(c.feature_b.index, 2);  // -y
        EXPECT_EQ(c.manifold_size, 4);
    }
}

TEST(HalfSpace, FeaturesInClosedFormCases) {
    const Shape box = Shape::box(Vec3(1, 2, 3));
    const Pose origin{};
    auto feature = [&](const Shape& b, const Vec3& n) {
        return contact(HalfSpace{n.normalized(), 0}, b, origin).feature_b;
    };
    // Box: face, edge, vertex (support along -n).
    EXPECT_EQ(feature(box, Vec3(0, 1, 0)).type, FeatureType::Face);
    EXPECT_EQ(feature(box, Vec3(0, 1, 0)).index, 2);   // -y face
    EXPECT_EQ(feature(box, Vec3(0, 0, -1)).index, 5);  // +z face
    EXPECT_EQ(feature(box, Vec3(0, 1, 1)).type, FeatureType::Edge);
    EXPECT_EQ(feature(box, Vec3(0, 1, 1)).index, 0);               // along x at y-, z-
    EXPECT_EQ(feature(box, Vec3(-1, 0, 1)).index, 4 * 1 + 1 + 0);  // along y at x+, z-
    EXPECT_EQ(feature(box, Vec3(1, 1, 1)).type, FeatureType::Vertex);
    EXPECT_EQ(feature(box, Vec3(1, 1, 1)).index, 0);
    EXPECT_EQ(feature(box, Vec3(-1, 1, -1)).index, 1 + 4);
    // Sphere: Face 0. Capsule: lying flat -> the cylinder, else the lower cap.
    EXPECT_EQ(feature(Shape::sphere(1), Vec3(1, 2, 3)).type, FeatureType::Face);
    const Shape capsule = Shape::capsule(0.5, 1);
    EXPECT_EQ(feature(capsule, Vec3(1, 0, 0)).type, FeatureType::Edge);
    EXPECT_EQ(feature(capsule, Vec3(1, 1, 0)).type, FeatureType::Vertex);
    EXPECT_EQ(feature(capsule, Vec3(1, 1, 0)).index, 0);  // support along -n: the bottom cap
    EXPECT_EQ(feature(capsule, Vec3(0, -1, 0)).index, 1);
    // A lying capsule touching the floor has both caps in the manifold.
    const ContactOutput lying =
        contact(HalfSpace{Vec3::UnitY(), 0}, capsule,
                Pose{Vec3(0, 0.5, 0),
                     Quat(Eigen::AngleAxis<Real>(std::numbers::pi_v<Real> / 2, Vec3::UnitZ()))});
    EXPECT_EQ(lying.state, ContactState::Touching);
    EXPECT_EQ(lying.manifold_size, 2);
    // Hull (a cube's 8 corners): face, edge and vertex by the vertices within tolerance.
    std::vector<Vec3> corners;
    for (int i = 0; i < 8; ++i)
        corners.emplace_back((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
    const Shape cube = Shape::convexHull(hullOf(corners));
    const auto& hull = *cube.hull;
    const auto face = feature(cube, Vec3(0, 1, 0));
    ASSERT_EQ(face.type, FeatureType::Face);
    for (const auto v : hull.faces[static_cast<std::size_t>(face.index)]) {
        EXPECT_EQ(hull.vertices[static_cast<std::size_t>(v)].y(), -1);
    }
    const auto edge = feature(cube, Vec3(1, 1, 0));
    ASSERT_EQ(edge.type, FeatureType::Edge);
    const auto& ef = hull.faces[static_cast<std::size_t>(edge.index / 3)];
    for (const int e : {edge.index % 3, (edge.index % 3 + 1) % 3}) {
        const Vec3& v = hull.vertices[static_cast<std::size_t>(ef[static_cast<std::size_t>(e)])];
        EXPECT_EQ(v.x(), -1);
        EXPECT_EQ(v.y(), -1);
    }
    const auto vertex = feature(cube, Vec3(1, 1, 1));
    ASSERT_EQ(vertex.type, FeatureType::Vertex);
    EXPECT_EQ(hull.vertices[static_cast<std::size_t>(vertex.index)], Vec3(-1, -1, -1));
    // A cube resting on a face gives a four-point manifold.
    EXPECT_EQ(contact(HalfSpace{Vec3::UnitY(), -1}, cube, origin).manifold_size, 4);
}

TEST(HalfSpace, BadInputFails) {
    const Shape box = Shape::box(Vec3(1, 1, 1));
    EXPECT_EQ(contact(HalfSpace{Vec3(0, 2, 0), 0}, box, Pose{}).state, ContactState::Failed);
    EXPECT_EQ(contact(HalfSpace{Vec3(0, std::nan(""), 0), 0}, box, Pose{}).state,
              ContactState::Failed);
    EXPECT_EQ(
        contact(HalfSpace{Vec3::UnitY(), std::numeric_limits<Real>::infinity()}, box, Pose{}).state,
        ContactState::Failed);
    const ContactOutput f = contact(box, Pose{}, HalfSpace{Vec3::Zero(), 0});
    EXPECT_EQ(f.state, ContactState::Failed);
    EXPECT_EQ(f.manifold_size, 0);
}

}  // namespace
