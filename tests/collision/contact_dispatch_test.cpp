// tests/collision/contact_dispatch_test.cpp -- contact()'s dispatch against its plain reference:
// the same pair routines (contact_pairs.h) called the straightforward way -- every number
// checked for finiteness one by one, the canonical key compared as arrays, the answer computed
// into a local ContactOutput, copied, and every world point transformed by the pose, manifold
// points included. contact() must give the same bits in every field, on random pairs of every
// convex family, meshes as hulls, and the adversarial ones: touching, coincident centres,
// identical inputs, far from the origin, scales 1e-4..1e4, non-finite input.
#include "collision/narrowphase/contact.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "collision/geometry/convex_hull.h"
#include "narrowphase/contact_pairs.h"
#include "narrowphase/contact_round.h"
#include "test_random.h"

namespace {

using collision::ContactOutput;
using collision::ContactState;
using collision::Pose;
using collision::Quat;
using collision::Real;
using collision::Shape;
using collision::ShapeType;
using collision::Vec3;
namespace pairs = collision::contact_pairs;

bool referenceIsFinite(const Shape& shape, const Pose& pose) {
    return std::isfinite(shape.radius) && std::isfinite(shape.half_height) &&
           shape.half_extents.allFinite() && pose.position.allFinite() &&
           pose.orientation.coeffs().allFinite();
}

bool referenceCanonicalLess(const Shape& a, const Pose& pose_a, const Shape& b,
                            const Pose& pose_b) {
    if (a.type != b.type) return a.type < b.type;
    const std::array<Real, 12> ka{
        pose_a.position.x(),    pose_a.position.y(),    pose_a.position.z(),
        pose_a.orientation.w(), pose_a.orientation.x(), pose_a.orientation.y(),
        pose_a.orientation.z(), a.radius,               a.half_height,
        a.half_extents.x(),     a.half_extents.y(),     a.half_extents.z()};
    const std::array<Real, 12> kb{
        pose_b.position.x(),    pose_b.position.y(),    pose_b.position.z(),
        pose_b.orientation.w(), pose_b.orientation.x(), pose_b.orientation.y(),
        pose_b.orientation.z(), b.radius,               b.half_height,
        b.half_extents.x(),     b.half_extents.y(),     b.half_extents.z()};
    if (ka != kb) return ka < kb;
    if (a.hull != b.hull) return std::less<>()(a.hull.get(), b.hull.get());
    return std::less<>()(a.mesh.get(), b.mesh.get());
}

collision::CollideOutput referenceRoutine(const Shape& a, const Shape& b,
                                          const collision::RelativePose& rel,
                                          const pairs::Ctx& ctx, pairs::Local& out) {
    if (a.type == ShapeType::Sphere && b.type == ShapeType::Sphere) {
        return pairs::sphereSphere(a, b, rel, ctx, out);
    }
    if (a.type == ShapeType::Sphere && b.type == ShapeType::Box) {
        return pairs::sphereBox(a, b, rel, ctx, out);
    }
    if (a.type == ShapeType::Sphere && b.type == ShapeType::Capsule) {
        return pairs::sphereCapsule(a, b, rel, ctx, out);
    }
    if (a.type == ShapeType::Capsule && b.type == ShapeType::Capsule) {
        return pairs::capsuleCapsule(a, b, rel, ctx, out);
    }
    if (a.type == ShapeType::Box && b.type == ShapeType::Box) {
        return pairs::boxBox(a, b, rel, ctx, out);
    }
    return pairs::convexConvex(a, b, rel, ctx, out);
}

void referenceSettle(const collision::CollideOutput& decided, Real tolerance, pairs::Local& local) {
    switch (decided.state) {
        case ContactState::Separated:
            local.signed_distance = std::max(local.signed_distance, decided.distance);
            break;
        case ContactState::Touching:
            local.signed_distance = std::clamp(local.signed_distance, -tolerance, tolerance);
            break;
        case ContactState::Penetrating:
            if (!(local.signed_distance < -tolerance)) {
                local.signed_distance =
                    std::nextafter(-tolerance, -std::numeric_limits<Real>::infinity());
            }
            break;
        case ContactState::Failed:
            break;
    }
    local.state = decided.state;
}

ContactOutput referenceContact(const Shape& a_in, const Pose& pose_a_in, const Shape& b_in,
                               const Pose& pose_b_in) {
    ContactOutput failed;
    if (!referenceIsFinite(a_in, pose_a_in) || !referenceIsFinite(b_in, pose_b_in)) return failed;
    Shape a_hull;
    Shape b_hull;
    const Shape* a = &a_in;
    const Shape* b = &b_in;
    if (a_in.type == ShapeType::Mesh) {
        a_hull = Shape::convexHull(a_in.hull);
        a = &a_hull;
    }
    if (b_in.type == ShapeType::Mesh) {
        b_hull = Shape::convexHull(b_in.hull);
        b = &b_hull;
    }
    const bool swap = referenceCanonicalLess(*b, pose_b_in, *a, pose_a_in);
    const Shape& first = swap ? *b : *a;
    const Shape& second = swap ? *a : *b;
    const Pose& pose_first = swap ? pose_b_in : pose_a_in;
    const Pose& pose_second = swap ? pose_a_in : pose_b_in;
    const pairs::Ctx ctx = collision::pairContext(first, second);
    const collision::RelativePose rel = collision::relativePose(pose_first, pose_second);
    pairs::Local local;
    local.state = ContactState::Touching;
    const collision::CollideOutput decided = referenceRoutine(first, second, rel, ctx, local);
    if (local.state != ContactState::Failed) referenceSettle(decided, ctx.tolerance, local);
    if (local.state == ContactState::Failed || !std::isfinite(local.signed_distance) ||
        !local.normal.allFinite() || !(std::abs(local.normal.squaredNorm() - 1) < Real(1e-6)) ||
        !local.point_a.allFinite() || !local.point_b.allFinite()) {
        failed.iterations = local.iterations;
        return failed;
    }
    if (local.state == ContactState::Separated) {
        local.manifold_size = 0;
    } else if (local.manifold_size == 0) {
        const bool polytopes =
            (first.type == ShapeType::Box || first.type == ShapeType::ConvexHull) &&
            (second.type == ShapeType::Box || second.type == ShapeType::ConvexHull);
        if (!polytopes || !pairs::polytopeManifold(first, second, rel, ctx, local)) {
            pairs::setSingleManifold(local);
        }
    }
    ContactOutput out = local;
    out.normal = pose_first.rotation() * local.normal;
    out.point_a = pose_first.apply(local.point_a);
    out.point_b = pose_first.apply(local.point_b);
    for (std::size_t k = 0; k < static_cast<std::size_t>(local.manifold_size); ++k) {
        out.manifold[k].point_a = pose_first.apply(local.manifold[k].point_a);
        out.manifold[k].point_b = pose_first.apply(local.manifold[k].point_b);
    }
    if (swap) {
        out.normal = -out.normal;
        std::swap(out.point_a, out.point_b);
        std::swap(out.feature_a, out.feature_b);
        for (std::size_t k = 0; k < static_cast<std::size_t>(out.manifold_size); ++k) {
            std::swap(out.manifold[k].point_a, out.manifold[k].point_b);
        }
    }
    return out;
}

bool sameBits(const Vec3& p, const Vec3& q) {
    return std::memcmp(p.data(), q.data(), 3 * sizeof(Real)) == 0;
}

bool sameBits(Real x, Real y) { return std::memcmp(&x, &y, sizeof(Real)) == 0; }

// Every field, bit for bit (unused manifold entries included); "" when equal.
std::string difference(const ContactOutput& got, const ContactOutput& want) {
    if (got.state != want.state) return "state";
    if (!sameBits(got.signed_distance, want.signed_distance)) return "signed_distance";
    if (!sameBits(got.normal, want.normal)) return "normal";
    if (!sameBits(got.point_a, want.point_a)) return "point_a";
    if (!sameBits(got.point_b, want.point_b)) return "point_b";
    if (got.feature_a.type != want.feature_a.type || got.feature_a.index != want.feature_a.index) {
        return "feature_a";
    }
    if (got.feature_b.type != want.feature_b.type || got.feature_b.index != want.feature_b.index) {
        return "feature_b";
    }
    if (got.manifold_size != want.manifold_size) return "manifold_size";
    if (got.iterations != want.iterations) return "iterations";
    for (std::size_t k = 0; k < got.manifold.size(); ++k) {
        if (!sameBits(got.manifold[k].point_a, want.manifold[k].point_a) ||
            !sameBits(got.manifold[k].point_b, want.manifold[k].point_b) ||
            !sameBits(got.manifold[k].depth, want.manifold[k].depth)) {
            return "manifold[" + std::to_string(k) + "]";
        }
    }
    return "";
}

Shape hullShape(const std::vector<Vec3>& points, bool as_mesh) {
    const auto out = collision::computeConvexHull(points);
    EXPECT_TRUE(out.ok) << out.error;
    auto hull = std::make_shared<const collision::ConvexPolytope>(out.hull);
    if (!as_mesh) return Shape::convexHull(hull);
    auto mesh = std::make_shared<collision::TriangleMesh>();
    mesh->vertices = hull->vertices;
    mesh->triangles = hull->faces;
    return Shape::triangleMesh(mesh, hull);
}

// Kinds 0..4: sphere, box, capsule, hull (a random point cloud's), mesh (the same as a mesh).
Shape randomShape(int kind, Real scale, cdlab_test::Rng& rng) {
    switch (kind) {
        case 0:
            return Shape::sphere(scale * rng.uniform(0.2, 1.5));
        case 1:
            return Shape::box(scale * rng.vec(0.2, 1.5));
        case 2:
            return Shape::capsule(scale * rng.uniform(0.2, 0.8), scale * rng.uniform(0.2, 1.5));
        default: {
            std::vector<Vec3> points;
            for (int i = 0; i < 10; ++i) points.push_back(scale * rng.vec(-1, 1));
            return hullShape(points, kind == 4);
        }
    }
}

TEST(ContactDispatch, BitIdenticalToTheReferenceDispatchOnRandomAndAdversarialPairs) {
    cdlab_test::Rng rng(2024);
    constexpr std::array<Real, 5> kScales{1e-4, 1e-2, 1, 1e2, 1e4};
    int compared = 0;
    int penetrating = 0;
    for (int kind_a = 0; kind_a < 5; ++kind_a) {
        for (int kind_b = 0; kind_b < 5; ++kind_b) {
            const int count = (kind_a < 3 && kind_b < 3) ? 3000 : 150;
            for (int i = 0; i < count; ++i) {
                const int mode = i % 8;
                const Real scale = kScales[static_cast<std::size_t>(i / 8 % 5)];
                Shape a = randomShape(kind_a, scale, rng);
                Shape b = randomShape(kind_b, scale, rng);
                const Vec3 origin = (mode == 6 ? Real(1e6) : Real(0)) * Vec3::Ones();
                const Pose pose_a{origin + scale * rng.vec(-1, 1), rng.rotation()};
                Pose pose_b{pose_a.position + scale * rng.uniform(0, 3.5) *
                                                  (rng.rotation() * Vec3::UnitX()),
                            rng.rotation()};
                if (mode == 1) pose_b.position = pose_a.position;  // coincident centres
                if (mode == 2) pose_b = pose_a;                     // coincident poses
                if (mode == 3) {                                    // identical inputs
                    b = a;
                    pose_b = pose_a;
                }
                if (mode == 4 && kind_a == 0 && kind_b == 0) {  // exactly touching spheres
                    pose_b.position = pose_a.position + Vec3(a.radius + b.radius, 0, 0);
                }
                if (mode == 5 && kind_a == 1 && kind_b == 1) {  // face to face, touching
                    pose_b.orientation = pose_a.orientation;
                    pose_b.position = pose_a.position +
                                      pose_a.orientation *
                                          Vec3(a.half_extents.x() + b.half_extents.x(),
                                               rng.uniform(-0.5, 0.5) * scale, 0);
                }
                if (mode == 7 && i % 64 == 7) {  // non-finite input
                    pose_b.position.y() = std::numeric_limits<Real>::quiet_NaN();
                }
                for (const bool swapped : {false, true}) {
                    const ContactOutput got = swapped ? collision::contact(b, pose_b, a, pose_a)
                                                      : collision::contact(a, pose_a, b, pose_b);
                    const ContactOutput want = swapped ? referenceContact(b, pose_b, a, pose_a)
                                                       : referenceContact(a, pose_a, b, pose_b);
                    ASSERT_EQ(difference(got, want), "")
                        << "kinds " << kind_a << "-" << kind_b << " pair " << i << " swapped "
                        << swapped;
                    ++compared;
                    if (got.state == ContactState::Penetrating) ++penetrating;
                }
            }
        }
    }
    // The set reaches the manifold paths, not only separated pairs.
    EXPECT_GT(penetrating, compared / 4);
}

}  // namespace
