// collision/src/narrowphase/contact_half_space.cpp -- contact() of a half-space with a convex
// shape, in closed form (half_space.h).
// Invariant: everything is computed in the shape's frame, where the plane is n_l . y + h0 = 0
// with n_l = R^T n and h0 = n . p - offset (the one subtraction of large numbers far from the
// origin), and moved to world once; the shape-first overload mirrors the same call, so the two
// orders are exact mirrors.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "collision/narrowphase/half_space.h"
#include "collision/narrowphase/narrow_phase.h"
#include "geometry/shape_measures.h"
#include "narrowphase/gjk.h"

namespace collision {

namespace {

// Vertices whose heights above the plane differ from the deepest by at most this times the
// shape's size belong to the support feature (the same tolerance as contact()'s features).
constexpr Real kFeatureRelative = std::max(Real(1e-9), Real(64) * kEpsilon);
// A normal farther than this from unit length is bad input (Failed).
constexpr Real kUnitTolerance = Real(1e-6);

// A point of the shape (its frame) with its height above the plane.
struct Candidate {
    Vec3 local = Vec3::Zero();
    Real height = 0;
    std::int32_t index = 0;  // vertex index (box bits, hull index), cap (0/1); ties: lowest first
};

// The box's support feature along -n: axis k is free (the feature spans it) when the two vertex
// heights along it differ by at most tol (2 |n_k| h_k); fixed axes take the sign that goes down.
Feature boxSupportFeature(const Vec3& half, const Vec3& n, Real tol) {
    int free_count = 0;
    int free_axis = -1;
    int fixed_axis = -1;
    int bits = 0;  // bit k: coordinate +half[k] (contact.h's vertex numbering)
    for (int k = 0; k < 3; ++k) {
        if (Real(2) * std::abs(n[k]) * half[k] <= tol) {
            ++free_count;
            free_axis = k;
        } else {
            fixed_axis = k;
            if (n[k] < 0) bits |= 1 << k;
        }
    }
    switch (free_count) {
        case 0:
            return {FeatureType::Vertex, bits};
        case 1: {
            // Edge parallel to the free axis k: 4k + bit_i + 2 bit_j, i < j the other two axes.
            const int i = free_axis == 0 ? 1 : 0;
            const int j = free_axis == 2 ? 1 : 2;
            return {FeatureType::Edge, 4 * free_axis + ((bits >> i) & 1) + 2 * ((bits >> j) & 1)};
        }
        case 2:
            return {FeatureType::Face, 2 * fixed_axis + ((bits >> fixed_axis) & 1)};
        default: {
            // A box smaller than the tolerance: the face facing the plane most.
            int k = 0;
            n.cwiseAbs().maxCoeff(&k);
            return {FeatureType::Face, 2 * k + (n[k] < 0 ? 1 : 0)};
        }
    }
}

// The hull's support feature: its vertices within tol of the deepest height `lowest` (heights
// n . v, recomputed with the same expression as the caller's, so the same values).
Feature hullSupportFeature(const ConvexPolytope& hull, const Vec3& n, Real lowest,
                           std::int32_t deepest, Real tol) {
    auto low = [&](std::int32_t v) {
        return n.dot(hull.vertices[static_cast<std::size_t>(v)]) <= lowest + tol;
    };
    int count = 0;
    for (std::size_t i = 0; i < hull.vertices.size() && count < 3; ++i) {
        count += low(static_cast<std::int32_t>(i)) ? 1 : 0;
    }
    if (count >= 3) {
        for (std::size_t f = 0; f < hull.faces.size(); ++f) {
            const auto& face = hull.faces[f];
            if (low(face[0]) && low(face[1]) && low(face[2])) {
                return {FeatureType::Face, static_cast<std::int32_t>(f)};
            }
        }
    }
    if (count >= 2) {
        // An edge from the deepest vertex to another low one: 3 f + k for face f's edge k.
        for (std::size_t f = 0; f < hull.faces.size(); ++f) {
            const auto& face = hull.faces[f];
            for (std::size_t k = 0; k < 3; ++k) {
                const std::int32_t v0 = face[k];
                const std::int32_t v1 = face[(k + 1) % 3];
                if ((v0 == deepest && low(v1)) || (v1 == deepest && low(v0))) {
                    return {FeatureType::Edge, static_cast<std::int32_t>(3 * f + k)};
                }
            }
        }
    }
    return {FeatureType::Vertex, deepest};
}

// Up to four manifold points among the points offered (in the touching band or below), chosen
// as they stream past without storing them (no allocation per query): all of them when there
// are at most four, else the deepest, then the extremes along two directions u, v of the plane
// (shape frame), without repeats. Ties keep the first offered.
class ManifoldPicker {
public:
    ManifoldPicker(const Vec3& n, Real h0, Real band)
        : n_(n), u_(n.unitOrthogonal()), v_(n.cross(u_)), h0_(h0), band_(band) {}

    void offer(const Vec3& y, std::int32_t index) {
        const Candidate c{y, n_.dot(y) + h0_, index};
        if (!(c.height <= band_)) return;
        if (count_ < 4) first_[static_cast<std::size_t>(count_)] = c;
        if (count_ == 0 || c.height < pick_[0].height) pick_[0] = c;
        if (count_ == 0 || u_.dot(y) > u_.dot(pick_[1].local)) pick_[1] = c;
        if (count_ == 0 || u_.dot(y) < u_.dot(pick_[2].local)) pick_[2] = c;
        if (count_ == 0 || v_.dot(y) > v_.dot(pick_[3].local)) pick_[3] = c;
        if (count_ == 0 || v_.dot(y) < v_.dot(pick_[4].local)) pick_[4] = c;
        ++count_;
    }

    int finish(std::array<Candidate, 4>& out) const {
        if (count_ <= 4) {
            std::copy(first_.begin(), first_.begin() + count_, out.begin());
            return count_;
        }
        int n = 0;
        for (const Candidate& c : pick_) {
            if (n == 4) break;
            bool seen = false;
            for (int k = 0; k < n; ++k)
                seen = seen || out[static_cast<std::size_t>(k)].index == c.index;
            if (!seen) out[static_cast<std::size_t>(n++)] = c;
        }
        return n;
    }

private:
    Vec3 n_, u_, v_;
    Real h0_;
    Real band_;
    int count_ = 0;
    std::array<Candidate, 4> first_{};
    std::array<Candidate, 5> pick_{};  // deepest, max u, min u, max v, min v
};

bool finiteShape(const Shape& shape, const Pose& pose) {
    return std::isfinite(shape.radius) && std::isfinite(shape.half_height) &&
           shape.half_extents.allFinite() && pose.position.allFinite() &&
           pose.orientation.coeffs().allFinite();
}

}  // namespace

ContactOutput contact(const HalfSpace& a, const Shape& b, const Pose& pose_b) {
    ContactOutput out;  // Failed, zero fields
    const Real normal_length = a.normal.norm();
    if (!a.normal.allFinite() || !std::isfinite(a.offset) || !finiteShape(b, pose_b) ||
        !(std::abs(normal_length - 1) <= kUnitTolerance)) {
        return out;
    }
    const Vec3 n = a.normal / normal_length;
    const Mat3 rot = pose_b.rotation();
    const Vec3 n_l = rot.transpose() * n;
    const Real h0 = n.dot(pose_b.position) - a.offset;  // height of b's origin
    const Real scale = boundingRadius(b);
    const Real feature_tol = kFeatureRelative * scale;
    const Real touch_tol = kTouchRelativeTolerance * scale;

    // The deepest point of b (its support along -n), its feature, and the manifold candidates.
    Vec3 deepest = Vec3::Zero();
    ManifoldPicker manifold(n_l, h0, touch_tol);
    auto consider = [&](const Vec3& y, std::int32_t index) { manifold.offer(y, index); };
    switch (b.type) {
        case ShapeType::Sphere: {
            deepest = supportPoint(b, -n_l);
            out.feature_b = {FeatureType::Face, 0};
            consider(deepest, 0);
            break;
        }
        case ShapeType::Box: {
            deepest = supportPoint(b, -n_l);
            out.feature_b = boxSupportFeature(b.half_extents, n_l, feature_tol);
            for (int bits = 0; bits < 8; ++bits) {
                const Vec3 y((bits & 1) ? b.half_extents.x() : -b.half_extents.x(),
                             (bits & 2) ? b.half_extents.y() : -b.half_extents.y(),
                             (bits & 4) ? b.half_extents.z() : -b.half_extents.z());
                consider(y, bits);
            }
            break;
        }
        case ShapeType::Capsule: {
            deepest = supportPoint(b, -n_l);
            const bool parallel = Real(2) * std::abs(n_l.y()) * b.half_height <= feature_tol;
            out.feature_b = parallel ? Feature{FeatureType::Edge, 0}
                                     : Feature{FeatureType::Vertex, deepest.y() < 0 ? 0 : 1};
            // The deepest point (on the lower cap), and the other end of the cylinder's lowest
            // line: the other cap centre moved by the radius along the part of -n across the
            // axis (a point of the surface; the other cap's own lowest point lies inside the
            // cylinder unless the axis is parallel to the plane). Axis along n: no second point.
            const int deep_cap = deepest.y() < 0 ? 0 : 1;
            consider(deepest, deep_cap);
            const Vec3 across(n_l.x(), 0, n_l.z());
            const Real across_len = across.norm();
            if (b.half_height > 0 && across_len > 0) {
                const Real y = deep_cap == 0 ? b.half_height : -b.half_height;
                consider(Vec3(0, y, 0) - across * (b.radius / across_len), 1 - deep_cap);
            }
            break;
        }
        case ShapeType::ConvexHull:
        case ShapeType::Mesh: {
            const ConvexPolytope& hull = *b.hull;
            if (hull.vertices.empty()) return out;
            Real lowest = std::numeric_limits<Real>::infinity();
            std::int32_t arg = 0;
            for (std::size_t i = 0; i < hull.vertices.size(); ++i) {
                const Real height = n_l.dot(hull.vertices[i]);
                if (height < lowest) {
                    lowest = height;
                    arg = static_cast<std::int32_t>(i);
                }
                consider(hull.vertices[i], static_cast<std::int32_t>(i));
            }
            deepest = hull.vertices[static_cast<std::size_t>(arg)];
            out.feature_b = hullSupportFeature(hull, n_l, lowest, arg, feature_tol);
            break;
        }
    }
    out.signed_distance = n_l.dot(deepest) + h0;
    out.state = classifySignedDistance(out.signed_distance, touch_tol).state;
    out.normal = n;
    out.point_b = pose_b.apply(deepest);
    out.point_a = out.point_b - n * out.signed_distance;
    out.feature_a = {FeatureType::Face, 0};
    if (isColliding(out.state)) {
        std::array<Candidate, 4> picked;
        out.manifold_size = manifold.finish(picked);
        for (int k = 0; k < out.manifold_size; ++k) {
            const Candidate& c = picked[static_cast<std::size_t>(k)];
            ManifoldPoint& m = out.manifold[static_cast<std::size_t>(k)];
            m.point_b = pose_b.apply(c.local);
            m.point_a = m.point_b - n * c.height;
            m.depth = std::max(Real(0), -c.height);
        }
    }
    return out;
}

ContactOutput contact(const Shape& a, const Pose& pose_a, const HalfSpace& b) {
    ContactOutput out = contact(b, a, pose_a);
    out.normal = -out.normal;
    std::swap(out.point_a, out.point_b);
    std::swap(out.feature_a, out.feature_b);
    for (int k = 0; k < out.manifold_size; ++k) {
        ManifoldPoint& m = out.manifold[static_cast<std::size_t>(k)];
        std::swap(m.point_a, m.point_b);
    }
    return out;
}

}  // namespace collision
