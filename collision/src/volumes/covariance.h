// collision/src/volumes/covariance.h -- the area-weighted covariance of a triangulated surface,
// the principal-axes fit shared by the bodies' OBBs (bounding_volumes.cpp) and the BVH node
// volumes (bvh_volumes.cpp). Private to collision.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "collision/math.h"

namespace collision {

/// Covariance of the surface of `count` triangles, corners(k) giving triangle k's corners, about
/// `origin` (Gottschalk 1996 §3, RTCD 4.4.3): for each triangle (p, q, r) with area A and
/// centroid m, C += A/12 (9 m m^T + p p^T + q q^T + r r^T), then C = C/A_total - mu mu^T. Sums
/// about a nearby origin stay small far from the world origin. Zero total area (degenerate
/// triangles) falls back to the covariance of `points`.
template <class Corners>
Mat3 surfaceCovariance(const Vec3& origin, std::size_t count, Corners&& corners,
                       const std::vector<Vec3>& points) {
    Mat3 second = Mat3::Zero();
    Vec3 mu = Vec3::Zero();
    Real area_total = 0;
    for (std::size_t k = 0; k < count; ++k) {
        const std::array<Vec3, 3> c = corners(k);
        const Vec3 p = c[0] - origin;
        const Vec3 q = c[1] - origin;
        const Vec3 r = c[2] - origin;
        const Real area = Real(0.5) * (q - p).cross(r - p).norm();
        const Vec3 m = (p + q + r) / Real(3);
        second += area / Real(12) *
                  (Real(9) * m * m.transpose() + p * p.transpose() + q * q.transpose() +
                   r * r.transpose());
        mu += area * m;
        area_total += area;
    }
    Mat3 cov;
    if (area_total > 0) {
        mu /= area_total;
        cov = second / area_total - mu * mu.transpose();
    } else {
        mu.setZero();
        for (const Vec3& p : points) mu += p - origin;
        mu /= Real(points.size());
        cov.setZero();
        for (const Vec3& p : points) {
            const Vec3 d = p - origin - mu;
            cov += d * d.transpose();
        }
    }
    return cov;
}

}  // namespace collision
