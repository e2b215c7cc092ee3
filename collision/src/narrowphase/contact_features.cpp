// collision/src/narrowphase/contact_features.cpp -- which feature of a shape (vertex, edge, face)
// a witness point lies on, in the numbering of contact.h.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "collision/assert.h"
#include "narrowphase/contact_pairs.h"

namespace collision::contact_pairs {

// Capsule features from the point on its core segment.
Feature capsuleFeature(Real half_height, const Vec3& core_point, Real tol) {
    if (core_point.y() <= -half_height + tol) return {FeatureType::Vertex, 0};
    if (core_point.y() >= half_height - tol) return {FeatureType::Vertex, 1};
    return {FeatureType::Edge, 0};
}

// Hull features: a vertex within tol; else the faces whose triangle holds p (within tol); one
// plane among them -> the lowest such face, two planes -> the edge they share.
Feature hullFeature(const ConvexPolytope& hull, const Vec3& p, Real tol) {
    for (std::size_t i = 0; i < hull.vertices.size(); ++i) {
        if ((hull.vertices[i] - p).squaredNorm() <= tol * tol) {
            return {FeatureType::Vertex, static_cast<std::int32_t>(i)};
        }
    }
    int first_face = -1;
    Vec3 first_normal = Vec3::Zero();
    for (std::size_t f = 0; f < hull.faces.size(); ++f) {
        const Vec3& v0 = hull.vertices[static_cast<std::size_t>(hull.faces[f][0])];
        const Vec3& v1 = hull.vertices[static_cast<std::size_t>(hull.faces[f][1])];
        const Vec3& v2 = hull.vertices[static_cast<std::size_t>(hull.faces[f][2])];
        const Vec3 n = (v1 - v0).cross(v2 - v0);
        const Real len = n.norm();
        if (!(len > 0)) continue;
        const Vec3 unit = n / len;
        if (std::abs(unit.dot(p - v0)) > tol) continue;
        // Inside the triangle: on the inner side of each edge, up to tol.
        const std::array<const Vec3*, 3> v{&v0, &v1, &v2};
        int on_edge = -1;
        bool inside = true;
        for (int e = 0; e < 3 && inside; ++e) {
            const Vec3& s = *v[static_cast<std::size_t>(e)];
            const Vec3& t = *v[static_cast<std::size_t>((e + 1) % 3)];
            const Vec3 edge = t - s;
            const Real edge_len = edge.norm();
            if (!(edge_len > 0)) continue;
            const Real inward = unit.cross(edge).dot(p - s) / edge_len;
            if (inward < -tol) inside = false;
            if (inward <= tol) on_edge = e;
        }
        if (!inside) continue;
        if (first_face < 0) {
            first_face = static_cast<int>(f);
            first_normal = unit;
            if (on_edge < 0) break;  // strictly inside one triangle
            continue;
        }
        if ((unit - first_normal).norm() > Real(1e-6)) {
            // Two distinct planes meet here: an edge of the polytope; name it by the first face.
            const Vec3& f0 = hull.vertices[static_cast<std::size_t>(hull.faces[first_face][0])];
            const Vec3& f1 = hull.vertices[static_cast<std::size_t>(hull.faces[first_face][1])];
            const Vec3& f2 = hull.vertices[static_cast<std::size_t>(hull.faces[first_face][2])];
            const std::array<const Vec3*, 3> w{&f0, &f1, &f2};
            int best_edge = 0;
            Real best_dist = std::numeric_limits<Real>::infinity();
            for (int e = 0; e < 3; ++e) {
                const Vec3& s = *w[static_cast<std::size_t>(e)];
                const Vec3 edge = *w[static_cast<std::size_t>((e + 1) % 3)] - s;
                const Real d = edge.cross(p - s).norm() / std::max(edge.norm(), tol);
                if (d < best_dist) {
                    best_dist = d;
                    best_edge = e;
                }
            }
            return {FeatureType::Edge, 3 * first_face + best_edge};
        }
    }
    if (first_face >= 0) return {FeatureType::Face, first_face};
    return {};
}

// Feature of a point of the shape's core (its own frame).
Feature coreFeature(const Shape& shape, const Vec3& core_point, Real tol) {
    switch (shape.type) {
        case ShapeType::Sphere:
            return {FeatureType::Face, 0};
        case ShapeType::Box:
            return boxFeature(shape.half_extents, core_point, tol);
        case ShapeType::Capsule:
            return capsuleFeature(shape.half_height, core_point, tol);
        case ShapeType::ConvexHull:
        case ShapeType::Mesh:
            return hullFeature(*shape.hull, core_point, tol);
    }
    return {};
}

}  // namespace collision::contact_pairs
