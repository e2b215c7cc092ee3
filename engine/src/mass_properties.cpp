// engine/src/mass_properties.cpp -- mass, centre of mass and inertia of every shape type.
// Primitives use closed forms; polyhedra (hull faces, mesh triangles) use the divergence-theorem
// volume integrals over their boundary triangles (Mirtich JGT 1996; the per-triangle form of
// Eberly, "Polyhedral Mass Properties (Revisited)", 2002). Inertia is always about the centre
// of mass, in the shape's frame.
#include "engine/mass_properties.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <map>
#include <sstream>
#include <string>
#include <numbers>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

namespace engine {

namespace {

using collision::kPi;
using collision::ShapeType;

// Signed volume below this fraction of the bounding box volume counts as "no volume": a flat or
// open-and-cancelling surface, never a solid.
constexpr Real kMinVolumeFraction = Real(1e3) * collision::kEpsilon;

// Given inertia tensors are symmetric, and satisfy the triangle inequality, to this fraction of
// their size (values typed with a few digits, or computed by another program, round).
constexpr Real kInertiaRelativeTolerance = Real(1e-9);

// Volume integrals of 1, x, y, z, x^2, y^2, z^2, xy, yz, zx over the solid (Eberly 2002 §3,
// Mirtich 1996 §3): each boundary triangle contributes through the divergence theorem.
struct VolumeIntegrals {
    std::array<Real, 10> v{};
};

// Eberly 2002, "Subexpressions": the polynomial pieces of the triangle integrals of w, w^2, w^3.
void subexpressions(Real w0, Real w1, Real w2, Real& f1, Real& f2, Real& f3, Real& g0, Real& g1,
                    Real& g2) {
    const Real temp0 = w0 + w1;
    f1 = temp0 + w2;
    const Real temp1 = w0 * w0;
    const Real temp2 = temp1 + w1 * temp0;
    f2 = temp2 + w2 * f1;
    f3 = w0 * temp1 + w1 * temp2 + w2 * f2;
    g0 = f2 + w0 * (f1 + w0);
    g1 = f2 + w1 * (f1 + w1);
    g2 = f2 + w2 * (f1 + w2);
}

// Integrals over the solid bounded by `triangles` (CCW from outside), with coordinates taken
// relative to `ref` so that a mesh far from the origin keeps its precision.
VolumeIntegrals integrate(const std::vector<collision::Vec3>& vertices,
                          const std::vector<std::array<std::int32_t, 3>>& triangles,
                          const Vec3& ref) {
    VolumeIntegrals out;
    std::array<Real, 10>& intg = out.v;
    for (const auto& t : triangles) {
        const Vec3 p0 = vertices[t[0]] - ref;
        const Vec3 p1 = vertices[t[1]] - ref;
        const Vec3 p2 = vertices[t[2]] - ref;
        const Real a1 = p1.x() - p0.x(), b1 = p1.y() - p0.y(), c1 = p1.z() - p0.z();
        const Real a2 = p2.x() - p0.x(), b2 = p2.y() - p0.y(), c2 = p2.z() - p0.z();
        // Edge cross product = twice the area-weighted normal.
        const Real d0 = b1 * c2 - b2 * c1;
        const Real d1 = a2 * c1 - a1 * c2;
        const Real d2 = a1 * b2 - a2 * b1;
        Real f1x, f2x, f3x, g0x, g1x, g2x;
        Real f1y, f2y, f3y, g0y, g1y, g2y;
        Real f1z, f2z, f3z, g0z, g1z, g2z;
        subexpressions(p0.x(), p1.x(), p2.x(), f1x, f2x, f3x, g0x, g1x, g2x);
        subexpressions(p0.y(), p1.y(), p2.y(), f1y, f2y, f3y, g0y, g1y, g2y);
        subexpressions(p0.z(), p1.z(), p2.z(), f1z, f2z, f3z, g0z, g1z, g2z);
        intg[0] += d0 * f1x;
        intg[1] += d0 * f2x;
        intg[2] += d1 * f2y;
        intg[3] += d2 * f2z;
        intg[4] += d0 * f3x;
        intg[5] += d1 * f3y;
        intg[6] += d2 * f3z;
        intg[7] += d0 * (p0.y() * g0x + p1.y() * g1x + p2.y() * g2x);
        intg[8] += d1 * (p0.z() * g0y + p1.z() * g1y + p2.z() * g2y);
        intg[9] += d2 * (p0.x() * g0z + p1.x() * g1z + p2.x() * g2z);
    }
    constexpr std::array<Real, 10> kMult = {
        Real(1) / 6,  Real(1) / 24, Real(1) / 24,  Real(1) / 24,  Real(1) / 60,
        Real(1) / 60, Real(1) / 60, Real(1) / 120, Real(1) / 120, Real(1) / 120};
    for (int i = 0; i < 10; ++i) intg[i] *= kMult[i];
    return out;
}

struct Polyhedron {
    const std::vector<Vec3>* vertices = nullptr;
    const std::vector<std::array<std::int32_t, 3>>* triangles = nullptr;
};

Polyhedron polyhedronOf(const collision::Shape& shape) {
    if (shape.type == ShapeType::ConvexHull && shape.hull) {
        return {&shape.hull->vertices, &shape.hull->faces};
    }
    if (shape.type == ShapeType::Mesh && shape.mesh) {
        return {&shape.mesh->vertices, &shape.mesh->triangles};
    }
    return {};
}

MassPropertiesOutput polyhedronMass(const Polyhedron& poly, Real density) {
    MassPropertiesOutput out;
    const std::vector<Vec3>& verts = *poly.vertices;
    const auto& tris = *poly.triangles;
    if (verts.empty() || tris.empty()) {
        out.error = "polyhedron has no triangles";
        return out;
    }
    for (const auto& t : tris) {
        for (const std::int32_t i : t) {
            if (i < 0 || static_cast<std::size_t>(i) >= verts.size()) {
                out.error = "triangle index out of range";
                return out;
            }
        }
    }
    if (const std::int64_t open = boundaryEdgeCount(tris); open != 0) {
        out.error = "mesh is not closed (" + std::to_string(open) + " boundary edge" +
                    (open == 1 ? "" : "s") + " have no opposite edge)";
        return out;
    }
    Vec3 lo = verts[tris[0][0]];
    Vec3 hi = lo;
    for (const auto& t : tris) {
        for (const std::int32_t i : t) {
            lo = lo.cwiseMin(verts[i]);
            hi = hi.cwiseMax(verts[i]);
        }
    }
    if (!lo.allFinite() || !hi.allFinite()) {
        out.error = "non-finite vertex";
        return out;
    }
    const Vec3 ref = (lo + hi) * Real(0.5);
    const VolumeIntegrals vi = integrate(verts, tris, ref);
    const std::array<Real, 10>& intg = vi.v;
    const Vec3 size = hi - lo;
    const Real box_volume = size.x() * size.y() * size.z();
    const Real volume = intg[0];
    if (!(volume > kMinVolumeFraction * box_volume) || !(volume > 0)) {
        out.error = volume < 0 ? "mesh is inward oriented (signed volume < 0)"
                               : "mesh encloses no volume (signed volume <= 0)";
        return out;
    }
    // Centre of mass and inertia about it (Eberly 2002 §3; parallel-axis theorem).
    const Vec3 c(intg[1] / volume, intg[2] / volume, intg[3] / volume);
    const Real ixx = intg[5] + intg[6] - volume * (c.y() * c.y() + c.z() * c.z());
    const Real iyy = intg[4] + intg[6] - volume * (c.z() * c.z() + c.x() * c.x());
    const Real izz = intg[4] + intg[5] - volume * (c.x() * c.x() + c.y() * c.y());
    const Real ixy = -(intg[7] - volume * c.x() * c.y());
    const Real iyz = -(intg[8] - volume * c.y() * c.z());
    const Real ixz = -(intg[9] - volume * c.z() * c.x());
    Mat3 inertia;
    inertia << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
    out.props.mass = density * volume;
    out.props.center_of_mass = ref + c;
    out.props.inertia = density * inertia;
    out.ok = true;
    return out;
}

}  // namespace

// Closed in the sense the divergence theorem needs: every directed edge a->b is matched by as
// many b->a (a 2-manifold satisfies this with one each).
std::int64_t boundaryEdgeCount(const std::vector<std::array<std::int32_t, 3>>& triangles) {
    std::map<std::pair<std::int32_t, std::int32_t>, int> balance;
    for (const auto& t : triangles) {
        for (int e = 0; e < 3; ++e) {
            const std::int32_t a = t[e];
            const std::int32_t b = t[(e + 1) % 3];
            if (a == b) continue;
            if (a < b) {
                ++balance[{a, b}];
            } else {
                --balance[{b, a}];
            }
        }
    }
    std::int64_t open = 0;
    for (const auto& [edge, count] : balance) open += count < 0 ? -count : count;
    return open;
}

std::string inertiaProblem(const Mat3& inertia) {
    if (!inertia.allFinite()) return "must be finite";
    const Real largest = inertia.cwiseAbs().maxCoeff();
    if ((inertia - inertia.transpose()).cwiseAbs().maxCoeff() > kInertiaRelativeTolerance * largest) {
        return "must be symmetric";
    }
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(inertia);
    if (eig.info() != Eigen::Success) return "has no principal moments";
    const Vec3 m = eig.eigenvalues();  // ascending
    std::ostringstream moments;
    moments << std::setprecision(6) << "principal moments " << m.x() << ", " << m.y() << ", "
            << m.z() << " kg m^2";
    if (!(m.x() > 0)) return "must be positive definite (" + moments.str() + ")";
    const Real slack = kInertiaRelativeTolerance * (m.x() + m.y() + m.z());
    if (m.z() > m.x() + m.y() + slack) {
        return "violates the triangle inequality of principal moments, largest <= sum of the "
               "other two (" +
               moments.str() + "): no mass distribution has it";
    }
    return "";
}

Real shapeVolume(const collision::Shape& shape) {
    switch (shape.type) {
        case ShapeType::Sphere:
            return Real(4) / 3 * kPi * std::pow(shape.radius, 3);
        case ShapeType::Box:
            return 8 * shape.half_extents.x() * shape.half_extents.y() * shape.half_extents.z();
        case ShapeType::Capsule: {
            const Real r = shape.radius;
            return kPi * r * r * (2 * shape.half_height) + Real(4) / 3 * kPi * r * r * r;
        }
        case ShapeType::ConvexHull:
        case ShapeType::Mesh: {
            const Polyhedron poly = polyhedronOf(shape);
            if (poly.vertices == nullptr || poly.triangles->empty()) return 0;
            const Vec3 ref = (*poly.vertices)[(*poly.triangles)[0][0]];
            return integrate(*poly.vertices, *poly.triangles, ref).v[0];
        }
    }
    return 0;
}

MassPropertiesOutput computeMassProperties(const collision::Shape& shape, Real density) {
    MassPropertiesOutput out;
    if (!(density > 0) || !std::isfinite(density)) {
        out.error = "density must be finite and > 0";
        return out;
    }
    switch (shape.type) {
        case ShapeType::Sphere: {
            const Real r = shape.radius;
            if (!(r > 0) || !std::isfinite(r)) break;
            const Real m = density * shapeVolume(shape);
            out.props.mass = m;
            out.props.inertia = Mat3::Identity() * (Real(2) / 5 * m * r * r);
            out.ok = true;
            return out;
        }
        case ShapeType::Box: {
            const Vec3 h = shape.half_extents;
            if (!h.allFinite() || !(h.minCoeff() > 0)) break;
            const Real m = density * shapeVolume(shape);
            // Solid cuboid, full edge 2h: I_xx = m (4h_y^2 + 4h_z^2) / 12.
            out.props.mass = m;
            out.props.inertia = Vec3(h.y() * h.y() + h.z() * h.z(), h.z() * h.z() + h.x() * h.x(),
                                     h.x() * h.x() + h.y() * h.y())
                                    .asDiagonal();
            out.props.inertia *= m / 3;
            out.ok = true;
            return out;
        }
        case ShapeType::Capsule: {
            const Real r = shape.radius;
            const Real h = shape.half_height;
            if (!(r > 0) || !(h >= 0) || !std::isfinite(r) || !std::isfinite(h)) break;
            // Cylinder of height 2h plus two hemispheres (each 2/3 pi r^3).
            const Real m_cyl = density * kPi * r * r * (2 * h);
            const Real m_hemi = density * Real(2) / 3 * kPi * r * r * r;
            // Axial: cylinder m r^2 / 2, each hemisphere 2/5 m r^2 (half a sphere).
            const Real i_axial = m_cyl * r * r / 2 + 2 * (Real(2) / 5 * m_hemi * r * r);
            // Transverse: cylinder m (r^2/4 + H^2/12) with H = 2h. A hemisphere about its own
            // centre of mass (3r/8 from its flat face) has 83/320 m r^2; its centre of mass is
            // h + 3r/8 from the capsule centre (parallel-axis shift).
            const Real d = h + Real(3) / 8 * r;
            const Real i_hemi = Real(83) / 320 * m_hemi * r * r + m_hemi * d * d;
            const Real i_trans = m_cyl * (r * r / 4 + (2 * h) * (2 * h) / 12) + 2 * i_hemi;
            out.props.mass = m_cyl + 2 * m_hemi;
            out.props.inertia = Vec3(i_trans, i_axial, i_trans).asDiagonal();
            out.ok = true;
            return out;
        }
        case ShapeType::ConvexHull:
        case ShapeType::Mesh: {
            const Polyhedron poly = polyhedronOf(shape);
            if (poly.vertices == nullptr) {
                out.error = "shape has no geometry";
                return out;
            }
            return polyhedronMass(poly, density);
        }
    }
    out.error = "shape has no volume (sizes must be finite and > 0)";
    return out;
}

}  // namespace engine
