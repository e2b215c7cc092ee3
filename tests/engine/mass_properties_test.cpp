// tests/engine/mass_properties_test.cpp -- closed forms against the polyhedral volume integrals.
#include "engine/mass_properties.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "collision/geometry/convex_hull.h"

namespace engine {
namespace {

using collision::ConvexPolytope;
using collision::Shape;
using collision::TriangleMesh;

using collision::kPi;

// A box mesh with 8 shared vertices and 12 outward CCW triangles.
TriangleMesh boxMesh(const Vec3& h, const Vec3& offset = Vec3::Zero()) {
    TriangleMesh m;
    for (int i = 0; i < 8; ++i) {
        m.vertices.push_back(
            offset + Vec3(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 4 ? h.z() : -h.z()));
    }
    // Quads CCW from outside, split into two triangles each.
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                             {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) {
        m.triangles.push_back({q[0], q[1], q[2]});
        m.triangles.push_back({q[0], q[2], q[3]});
    }
    return m;
}

Shape meshShape(const TriangleMesh& m) {
    const collision::ConvexHullOutput hull = collision::computeConvexHull(m.vertices);
    EXPECT_TRUE(hull.ok) << hull.error;
    return Shape::triangleMesh(std::make_shared<const TriangleMesh>(m),
                               std::make_shared<const ConvexPolytope>(hull.hull));
}

Shape hullShape(const std::vector<Vec3>& points) {
    const collision::ConvexHullOutput hull = collision::computeConvexHull(points);
    EXPECT_TRUE(hull.ok) << hull.error;
    return Shape::convexHull(std::make_shared<const ConvexPolytope>(hull.hull));
}

void expectMatNear(const Mat3& a, const Mat3& b, Real rel) {
    const Real scale = b.norm();
    EXPECT_LE((a - b).norm(), rel * scale) << "got\n" << a << "\nexpected\n" << b;
}

TEST(MassProperties, SphereClosedForm) {
    const MassPropertiesOutput out = computeMassProperties(Shape::sphere(0.5), 1000);
    ASSERT_TRUE(out.ok) << out.error;
    const Real m = 1000 * 4.0 / 3.0 * kPi * 0.125;
    EXPECT_NEAR(out.props.mass, m, 1e-9 * m);
    EXPECT_EQ(out.props.center_of_mass, Vec3::Zero());
    expectMatNear(out.props.inertia, Mat3::Identity() * (0.4 * m * 0.25), 1e-12);
}

TEST(MassProperties, BoxClosedForm) {
    const Vec3 h(0.5, 0.3, 0.2);
    const MassPropertiesOutput out = computeMassProperties(Shape::box(h), 2);
    ASSERT_TRUE(out.ok) << out.error;
    const Real m = 2 * 1.0 * 0.6 * 0.4;
    EXPECT_NEAR(out.props.mass, m, 1e-12);
    // m/12 (b^2 + c^2) with full edges a, b, c.
    const Mat3 expected =
        Vec3(m / 12 * (0.36 + 0.16), m / 12 * (1.0 + 0.16), m / 12 * (1.0 + 0.36)).asDiagonal();
    expectMatNear(out.props.inertia, expected, 1e-12);
}

TEST(MassProperties, BoxAsHullAndMeshEqualsClosedForm) {
    const Vec3 h(0.5, 0.3, 0.2);
    const MassPropertiesOutput box = computeMassProperties(Shape::box(h), 7);
    const TriangleMesh mesh = boxMesh(h);
    const MassPropertiesOutput as_mesh = computeMassProperties(meshShape(mesh), 7);
    const MassPropertiesOutput as_hull = computeMassProperties(hullShape(mesh.vertices), 7);
    ASSERT_TRUE(box.ok && as_mesh.ok && as_hull.ok) << as_mesh.error << as_hull.error;
    for (const MassPropertiesOutput* o : {&as_mesh, &as_hull}) {
        EXPECT_NEAR(o->props.mass, box.props.mass, 1e-12 * box.props.mass);
        EXPECT_LE(o->props.center_of_mass.norm(), 1e-14);
        expectMatNear(o->props.inertia, box.props.inertia, 1e-12);
    }
    EXPECT_NEAR(shapeVolume(meshShape(mesh)), 8 * 0.5 * 0.3 * 0.2, 1e-14);
}

// The unit corner tetrahedron: V = 1/6, COM = (1/4,1/4,1/4), about the COM I_xx = 1/80 and
// I_xy = +1/480 (products of inertia enter with a minus sign: -(1/120 - V/16)).
TEST(MassProperties, CornerTetrahedronAnalytic) {
    const std::vector<Vec3> pts = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
    const MassPropertiesOutput out = computeMassProperties(hullShape(pts), 1);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_NEAR(out.props.mass, 1.0 / 6, 1e-15);
    EXPECT_LE((out.props.center_of_mass - Vec3::Constant(0.25)).norm(), 1e-15);
    Mat3 expected;
    expected << 1.0 / 80, 1.0 / 480, 1.0 / 480, 1.0 / 480, 1.0 / 80, 1.0 / 480, 1.0 / 480,
        1.0 / 480, 1.0 / 80;
    expectMatNear(out.props.inertia, expected, 1e-12);
}

TEST(MassProperties, OffsetMeshGivesCentreOfMassAndSameInertia) {
    const Vec3 h(0.4, 0.7, 0.25);
    for (const Vec3& offset : {Vec3(3, -2, 5), Vec3(1e6, -1e6, 2e6)}) {
        const MassPropertiesOutput out = computeMassProperties(meshShape(boxMesh(h, offset)), 500);
        ASSERT_TRUE(out.ok) << out.error;
        EXPECT_LE((out.props.center_of_mass - offset).norm(), 1e-9 * (1 + offset.norm()));
        const MassPropertiesOutput box = computeMassProperties(Shape::box(h), 500);
        EXPECT_NEAR(out.props.mass, box.props.mass, 1e-9 * box.props.mass);
        expectMatNear(out.props.inertia, box.props.inertia, 1e-9);
    }
}

// Points on a capsule surface (rings on the two hemispheres and the two rims of the cylinder);
// their hull is the tessellated capsule.
std::vector<Vec3> capsulePoints(Real r, Real h, int segments, int rings) {
    std::vector<Vec3> pts;
    for (int side : {-1, 1}) {
        pts.emplace_back(0, side * (h + r), 0);
        for (int i = 0; i < rings; ++i) {
            const Real phi = kPi / 2 * i / rings;  // 0 at the rim, towards the pole
            for (int j = 0; j < segments; ++j) {
                const Real theta = 2 * kPi * j / segments;
                pts.emplace_back(r * std::cos(phi) * std::cos(theta),
                                 side * (h + r * std::sin(phi)),
                                 r * std::cos(phi) * std::sin(theta));
            }
        }
    }
    return pts;
}

TEST(MassProperties, CapsuleMatchesTessellatedMesh) {
    const Real r = 0.3;
    const Real h = 0.6;
    const MassPropertiesOutput exact = computeMassProperties(Shape::capsule(r, h), 1000);
    ASSERT_TRUE(exact.ok);
    const Real expected_mass = 1000 * (kPi * r * r * 2 * h + 4.0 / 3 * kPi * r * r * r);
    EXPECT_NEAR(exact.props.mass, expected_mass, 1e-12 * expected_mass);
    const Shape hull = hullShape(capsulePoints(r, h, 256, 64));
    const collision::TriangleMesh mesh{hull.hull->vertices, hull.hull->faces};
    const MassPropertiesOutput tess = computeMassProperties(meshShape(mesh), 1000);
    ASSERT_TRUE(tess.ok) << tess.error;
    // Inscribed polygons lose ~ (2 pi / 256)^2 / 6 ~ 1e-4 of the volume.
    EXPECT_NEAR(tess.props.mass, exact.props.mass, 5e-4 * exact.props.mass);
    EXPECT_LE(tess.props.center_of_mass.norm(), 1e-9);
    expectMatNear(tess.props.inertia, exact.props.inertia, 1e-3);
    // The hemisphere shift matters: without it I_xx would be off by far more than 1e-3.
    EXPECT_GT(exact.props.inertia(0, 0), 1.2 * exact.props.inertia(1, 1));
}

TEST(MassProperties, ZeroHeightCapsuleIsASphere) {
    const MassPropertiesOutput cap = computeMassProperties(Shape::capsule(0.4, 0), 3);
    const MassPropertiesOutput sph = computeMassProperties(Shape::sphere(0.4), 3);
    ASSERT_TRUE(cap.ok && sph.ok);
    EXPECT_NEAR(cap.props.mass, sph.props.mass, 1e-12);
    expectMatNear(cap.props.inertia, sph.props.inertia, 1e-12);
}

TEST(MassProperties, SphereMatchesFineTessellation) {
    std::vector<Vec3> pts;
    const int rings = 96;
    const int segments = 192;
    pts.emplace_back(0, 1, 0);
    pts.emplace_back(0, -1, 0);
    for (int i = 1; i < rings; ++i) {
        const Real phi = kPi * i / rings;
        for (int j = 0; j < segments; ++j) {
            const Real theta = 2 * kPi * j / segments;
            pts.emplace_back(std::sin(phi) * std::cos(theta), std::cos(phi),
                             std::sin(phi) * std::sin(theta));
        }
    }
    const MassPropertiesOutput tess = computeMassProperties(hullShape(pts), 1);
    const MassPropertiesOutput exact = computeMassProperties(Shape::sphere(1), 1);
    ASSERT_TRUE(tess.ok && exact.ok) << tess.error;
    EXPECT_NEAR(tess.props.mass, exact.props.mass, 1e-3 * exact.props.mass);
    expectMatNear(tess.props.inertia, exact.props.inertia, 2e-3);
}

TEST(MassProperties, OpenMeshIsAnError) {
    TriangleMesh m = boxMesh(Vec3(1, 1, 1));
    m.triangles.pop_back();
    const MassPropertiesOutput out = computeMassProperties(meshShape(m), 1000);
    EXPECT_FALSE(out.ok);
    EXPECT_NE(out.error.find("not closed"), std::string::npos) << out.error;
}

TEST(MassProperties, BoundaryEdgesAreCounted) {
    TriangleMesh m = boxMesh(Vec3(1, 1, 1));
    EXPECT_EQ(boundaryEdgeCount(m.triangles), 0);
    // One quad face (two triangles) missing: its four edges are the boundary.
    m.triangles.pop_back();
    EXPECT_EQ(boundaryEdgeCount(m.triangles), 3);
    m.triangles.pop_back();
    EXPECT_EQ(boundaryEdgeCount(m.triangles), 4);
    const MassPropertiesOutput out = computeMassProperties(meshShape(m), 1000);
    EXPECT_NE(out.error.find("4 boundary edges"), std::string::npos) << out.error;
}

TEST(MassProperties, InertiaProblems) {
    EXPECT_EQ(inertiaProblem(Vec3(1, 2, 2.5).asDiagonal()), "");
    // A flat lamina: I_z = I_x + I_y exactly is a valid tensor.
    EXPECT_EQ(inertiaProblem(Vec3(1, 2, 3).asDiagonal()), "");
    // The unit cube's tensor rotated: not diagonal, still valid.
    const Mat3 r = Eigen::AngleAxis<Real>(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    EXPECT_EQ(inertiaProblem(r * Vec3(1, 1.5, 2).asDiagonal() * r.transpose()), "");
    EXPECT_NE(inertiaProblem(Vec3(1, 0, 1).asDiagonal()).find("positive definite"),
              std::string::npos);
    EXPECT_NE(inertiaProblem(Vec3(1, -1, 1).asDiagonal()).find("positive definite"),
              std::string::npos);
    EXPECT_NE(inertiaProblem(Vec3(1, 1, 3).asDiagonal()).find("triangle inequality"),
              std::string::npos);
    Mat3 asym = Mat3::Identity();
    asym(0, 1) = 0.1;
    EXPECT_EQ(inertiaProblem(asym), "must be symmetric");
    Mat3 nan = Mat3::Identity();
    nan(2, 2) = std::nan("");
    EXPECT_EQ(inertiaProblem(nan), "must be finite");
    // The triangle inequality holds for every principal frame: a rotated violation is caught.
    EXPECT_NE(inertiaProblem(r * Vec3(1, 1, 3).asDiagonal() * r.transpose())
                  .find("triangle inequality"),
              std::string::npos);
}

TEST(MassProperties, InwardMeshIsAnError) {
    TriangleMesh m = boxMesh(Vec3(1, 1, 1));
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
    const MassPropertiesOutput out = computeMassProperties(meshShape(m), 1000);
    EXPECT_FALSE(out.ok);
    EXPECT_NE(out.error.find("inward"), std::string::npos) << out.error;
    EXPECT_LT(shapeVolume(meshShape(m)), 0);
}

TEST(MassProperties, BadDensityOrSizeIsAnError) {
    EXPECT_FALSE(computeMassProperties(Shape::sphere(1), 0).ok);
    EXPECT_FALSE(computeMassProperties(Shape::sphere(1), -1).ok);
    EXPECT_FALSE(computeMassProperties(Shape::sphere(1), std::nan("")).ok);
    EXPECT_FALSE(computeMassProperties(Shape::sphere(0), 1).ok);
    EXPECT_FALSE(computeMassProperties(Shape::box(Vec3(1, 0, 1)), 1).ok);
    EXPECT_FALSE(computeMassProperties(Shape::capsule(0, 1), 1).ok);
}

}  // namespace
}  // namespace engine
