// tests/collision/contact_reference_test.cpp -- contact()'s penetration depth against the
// brute-force projection-overlap reference (contact_reference.h): exact for box/hull pairs (every
// SAT axis of A - B is a candidate), an upper bound for pairs with a round shape. The reference
// itself is first checked against closed forms.
#include "collision/narrowphase/contact_reference.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <vector>

#include "collision/geometry/convex_hull.h"
#include "collision/narrowphase/contact.h"
#include "test_random.h"
#include "test_scale.h"
#include "test_shapes.h"

namespace {

using cdlab_test::boundingRadius;

using collision::contact;
using collision::ContactOutput;
using collision::ContactState;
using collision::ConvexPolytope;
using collision::minimumOverlapReference;
using collision::OverlapReference;
using collision::Pose;
using collision::projectionOverlap;
using collision::Real;
using collision::Shape;
using collision::ShapeType;
using collision::Vec3;

// EPA's depth is accurate to kEpaRelativeTolerance (1e-11) * size; the reference's projections
// round at ~1e-15 * size. 1e-9 * size leaves room for both and still catches a wrong face.
constexpr Real kDepthRelative = 1e-9;

Shape hullOf(const std::vector<Vec3>& points) {
    const auto out = collision::computeConvexHull(points);
    EXPECT_TRUE(out.ok) << out.error;
    return Shape::convexHull(std::make_shared<const ConvexPolytope>(out.hull));
}

Shape boxHull(const Vec3& h) {
    std::vector<Vec3> corners;
    for (int i = 0; i < 8; ++i) {
        corners.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                             (i & 4) ? h.z() : -h.z());
    }
    return hullOf(corners);
}

Shape randomHull(cdlab_test::Rng& rng, Real size, int points) {
    std::vector<Vec3> p;
    const Vec3 stretch = rng.vec(0.4, 1.0);
    for (int i = 0; i < points; ++i) {
        Vec3 v = rng.vec(-1, 1);
        if (v.norm() < 1e-3) v = Vec3::UnitX();
        p.push_back(size * v.normalized().cwiseProduct(stretch));
    }
    return hullOf(p);
}

// Axis-aligned boxes: the overlap is the smallest per-axis interval overlap (exact), and the
// reference's axis is that coordinate axis pointing from A to B; spheres: the sampled overlap is
// within the sampling error above r_a + r_b - |d|.
TEST(ContactReference, MatchesClosedForms) {
    cdlab_test::Rng rng(21);
    int penetrating = 0;
    for (int n = 0; n < 500; ++n) {
        const Vec3 ha = rng.vec(0.2, 1.5);
        const Vec3 hb = rng.vec(0.2, 1.5);
        const Pose pa{rng.vec(-1, 1), collision::Quat::Identity()};
        const Pose pb{pa.position + rng.vec(-2, 2), collision::Quat::Identity()};
        const Vec3 t = pb.position - pa.position;
        const Vec3 overlap = ha + hb - t.cwiseAbs();
        for (const bool as_hulls : {false, true}) {
            const Shape a = as_hulls ? boxHull(ha) : Shape::box(ha);
            const Shape b = as_hulls ? boxHull(hb) : Shape::box(hb);
            const OverlapReference ref = minimumOverlapReference(a, pa, b, pb);
            ASSERT_TRUE(ref.exact);
            if ((overlap.array() > 0).all()) {
                ASSERT_NEAR(ref.overlap, overlap.minCoeff(), 1e-12) << n;
                int k = 0;
                overlap.minCoeff(&k);
                ASSERT_NEAR(ref.axis[k] * (t[k] < 0 ? -1 : 1), 1, 1e-12) << n;
                ++penetrating;
            } else {
                // Separated: the largest per-axis gap is a lower bound on the distance.
                ASSERT_LE(ref.overlap, -(-overlap).maxCoeff() + 1e-12) << n;
                ASSERT_LT(ref.overlap, 0) << n;
            }
        }
        const Shape sa = Shape::sphere(rng.uniform(0.2, 1.5));
        const Shape sb = Shape::sphere(rng.uniform(0.2, 1.5));
        const OverlapReference ref = minimumOverlapReference(sa, pa, sb, pb);
        ASSERT_FALSE(ref.exact);
        const Real exact = sa.radius + sb.radius - t.norm();
        // 2048 Fibonacci directions: spacing ~0.08 rad, overlap error <= |d| (1 - cos 0.08).
        ASSERT_GE(ref.overlap, exact - 1e-12) << n;
        ASSERT_LE(ref.overlap, exact + 4e-3 * t.norm()) << n;
    }
    EXPECT_GT(penetrating, 100);
}

// The depth of contact() (EPA for hulls and box-hull pairs, SAT for box-box) equals the exact
// reference on thousands of random penetrating polytope pairs, within kDepthRelative * size.
TEST(ContactReference, PolytopeDepthEqualsMinimumOverlap) {
    cdlab_test::Rng rng(22);
    int penetrating = 0;
    int separated = 0;
    Real worst = 0;
    for (int n = 0; n < 4000; ++n) {
        const int kind = n % 4;  // hull-hull, box-hull, boxhull-boxhull, box-box
        const Shape a = kind == 3   ? Shape::box(rng.vec(0.2, 1.5))
                        : kind == 2 ? boxHull(rng.vec(0.2, 1.5))
                        : kind == 1 ? Shape::box(rng.vec(0.2, 1.5))
                                    : randomHull(rng, rng.uniform(0.3, 1.5), 12);
        const Shape b = kind == 3   ? Shape::box(rng.vec(0.2, 1.5))
                        : kind == 2 ? boxHull(rng.vec(0.2, 1.5))
                                    : randomHull(rng, rng.uniform(0.3, 1.5), 12);
        const Real reach = boundingRadius(a) + boundingRadius(b);
        const Pose pa{rng.vec(-1, 1), rng.rotation()};
        const Pose pb{pa.position + rng.uniform(0, 0.8) * reach * (rng.rotation() * Vec3::UnitX()),
                      rng.rotation()};
        const OverlapReference ref = minimumOverlapReference(a, pa, b, pb, 0);
        ASSERT_TRUE(ref.exact);
        const Real scale = std::max(boundingRadius(a), boundingRadius(b));
        const ContactOutput out = contact(a, pa, b, pb);
        ASSERT_NE(out.state, ContactState::Failed) << n;
        if (ref.overlap > 1e-6 * scale) {
            ++penetrating;
            ASSERT_EQ(out.state, ContactState::Penetrating) << n;
            const Real depth = -out.signed_distance;
            ASSERT_NEAR(depth, ref.overlap, kDepthRelative * scale)
                << n << " kind " << kind << " axis " << ref.axis.transpose() << " normal "
                << out.normal.transpose();
            worst = std::max(worst, std::abs(depth - ref.overlap) / scale);
            // The normal attains the depth: the overlap along it is the depth.
            ASSERT_NEAR(projectionOverlap(a, pa, b, pb, out.normal), depth, kDepthRelative * scale)
                << n;
        } else if (ref.overlap < -1e-6 * scale) {
            ++separated;
            ASSERT_EQ(out.state, ContactState::Separated) << n;
            // -overlap is a separating-axis lower bound on the distance.
            ASSERT_GE(out.signed_distance, -ref.overlap - kDepthRelative * scale) << n;
        }
    }
    EXPECT_GT(penetrating, 2000);
    EXPECT_GT(separated, 200);
    std::ostringstream worst_text;
    worst_text << worst;
    RecordProperty("worst_relative_depth_error", worst_text.str());
}

// Pairs with a round shape: the sampled reference is an upper bound on the depth, so the depth of
// contact() is never larger than it by more than kDepthRelative * size, and not much smaller
// either: 8192 directions are ~0.04 rad apart, and near a hull edge the overlap grows linearly
// with the angle (0.02 * size allowed).
TEST(ContactReference, RoundPairDepthWithinSampledOverlap) {
    cdlab_test::Rng rng(23);
    int penetrating = 0;
    const int trials = cdlab_test::scaled(1200, 240);
    for (int n = 0; n < trials; ++n) {
        const Shape round = n % 2 == 0 ? Shape::sphere(rng.uniform(0.2, 1.2))
                                       : Shape::capsule(rng.uniform(0.1, 0.6), rng.uniform(0.1, 1));
        const Shape other =
            n % 3 == 0 ? Shape::box(rng.vec(0.2, 1.5)) : randomHull(rng, rng.uniform(0.3, 1.5), 12);
        const Real reach = boundingRadius(round) + boundingRadius(other);
        const Pose pa{rng.vec(-1, 1), rng.rotation()};
        const Pose pb{pa.position + rng.uniform(0, 0.8) * reach * (rng.rotation() * Vec3::UnitX()),
                      rng.rotation()};
        const OverlapReference ref = minimumOverlapReference(other, pa, round, pb, 8192);
        ASSERT_FALSE(ref.exact);
        const Real scale = std::max(boundingRadius(round), boundingRadius(other));
        if (!(ref.overlap > 0.05 * scale)) continue;
        const ContactOutput out = contact(other, pa, round, pb);
        ASSERT_EQ(out.state, ContactState::Penetrating) << n;
        ++penetrating;
        const Real depth = -out.signed_distance;
        ASSERT_LE(depth, ref.overlap + kDepthRelative * scale) << n;
        ASSERT_GE(depth, ref.overlap - 2e-2 * scale) << n;
    }
    EXPECT_GT(penetrating, trials / 4);
}

// Every convex pair type: contact()'s signed distance lies within the reference bounds (closed
// forms for sphere/capsule pairs and sphere-box, the overlap reference otherwise), and the closed
// forms and penetrating polytopes pin it down to 1e-9 * size.
TEST(ContactReference, SignedDistanceWithinReferenceBoundsForEveryPair) {
    cdlab_test::Rng rng(24);
    const std::vector<Shape> zoo{Shape::sphere(0.6),        Shape::box(Vec3(0.8, 0.5, 0.3)),
                                 Shape::capsule(0.3, 0.6),  randomHull(rng, 0.9, 16),
                                 Shape::capsule(0.15, 1.0), boxHull(Vec3(0.2, 1.0, 0.6))};
    int pinned = 0;
    for (const Shape& a : zoo) {
        for (const Shape& b : zoo) {
            for (int n = 0; n < 150; ++n) {
                const Real reach = boundingRadius(a) + boundingRadius(b);
                const Real scale = std::max(boundingRadius(a), boundingRadius(b));
                const Pose pa{rng.vec(-1, 1), rng.rotation()};
                const Pose pb{
                    pa.position + rng.uniform(0, 1.2) * reach * (rng.rotation() * Vec3::UnitX()),
                    rng.rotation()};
                const collision::SignedDistanceBounds ref =
                    collision::signedDistanceReference(a, pa, b, pb, 512);
                const ContactOutput out = contact(a, pa, b, pb);
                ASSERT_NE(out.state, ContactState::Failed);
                ASSERT_GE(out.signed_distance, ref.lower - kDepthRelative * scale)
                    << n << " " << static_cast<int>(a.type) << " " << static_cast<int>(b.type);
                ASSERT_LE(out.signed_distance, ref.upper + kDepthRelative * scale)
                    << n << " " << static_cast<int>(a.type) << " " << static_cast<int>(b.type);
                if (ref.upper == ref.lower) ++pinned;
            }
        }
    }
    EXPECT_GT(pinned, 1500);
}

}  // namespace
