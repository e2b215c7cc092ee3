// engine/src/response_stage.cpp -- see response_stage.h.
#include "response_stage.h"

#include <Eigen/Geometry>

namespace engine {

ResponseStage::ResponseStage(const WorldSettings& settings) : finder_(settings.broad_phase) {
    // The six faces of the bounds, solid outside: -x, +x, -y, +y, -z, +z.
    for (int k = 0; k < 3; ++k) {
        for (const Real side : {Real(-1), Real(1)}) {
            Wall w;
            w.plane.normal = Vec3::Zero();
            w.plane.normal[k] = -side;  // out of the solid, into the world
            w.plane.offset = side < 0 ? settings.bounds.min[k] : -settings.bounds.max[k];
            w.restitution = settings.restitution;
            w.friction = settings.friction;
            walls_.push_back(w);
        }
    }
}

void ResponseStage::solve(std::span<Body> bodies,
                          std::span<const collision::ProxyVolumes> volumes,
                          const WorldSettings& settings, Real dt) {
    for (Body& b : bodies) {
        if (!b.is_static) b.linear_momentum += b.mass * settings.gravity * dt;
    }
    const ContactSolverSettings solver_settings;
    findPairs(bodies, volumes, settings.bounds, solver_settings.margin_fraction);
    solver_.solve(bodies, pairs_, walls_, wall_candidates_, dt, solver_settings, pseudo_linear_,
                  pseudo_angular_);
    solver_.pushedPairs(pushed_);
}

void ResponseStage::findPairs(std::span<const Body> bodies,
                              std::span<const collision::ProxyVolumes> volumes,
                              const collision::Aabb& bounds, Real margin_fraction) {
    // The AABBs of the last detection grown by margin_fraction times each body's bounding
    // radius (the exact AABBs of resting bodies barely touch, and lose their pair the moment the
    // solver lifts one by a hair), paired by the scene's broad phase. Output sorted, a < b.
    const std::size_t n = bodies.size();
    grown_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Body& b = bodies[i];
        const Real r = b.local_bounds.sphere.center.norm() + b.local_bounds.sphere.radius;
        grown_[i].min = volumes[i].aabb.min - Vec3::Constant(margin_fraction * r);
        grown_[i].max = volumes[i].aabb.max + Vec3::Constant(margin_fraction * r);
    }
    finder_.find(
        grown_,
        [bodies](BodyId i, BodyId j) { return !(bodies[i].is_static && bodies[j].is_static); },
        pairs_);
    // Bodies whose grown AABB reaches a face of the bounds, by wall then body.
    wall_candidates_.clear();
    for (std::uint32_t w = 0; w < walls_.size(); ++w) {
        const int k = static_cast<int>(w / 2);
        const bool low = w % 2 == 0;
        for (std::size_t i = 0; i < n; ++i) {
            if (bodies[i].is_static) continue;
            if (low ? grown_[i].min[k] <= bounds.min[k] : grown_[i].max[k] >= bounds.max[k]) {
                wall_candidates_.push_back({w, static_cast<BodyId>(i)});
            }
        }
    }
}

void ResponseStage::correctPositions(std::span<Body> bodies, Real dt) const {
    for (std::size_t i = 0; i < bodies.size(); ++i) {
        Body& b = bodies[i];
        if (b.is_static) continue;
        b.position += pseudo_linear_[i] * dt;
        const Vec3 turn = pseudo_angular_[i] * dt;
        const Real angle = turn.norm();
        if (angle > 0) {
            // L turns with the body, so the correction leaves 1/2 L.I^-1 L unchanged.
            const Quat r(Eigen::AngleAxis<Real>(angle, turn / angle));
            b.orientation = (r * b.orientation).normalized();
            b.angular_momentum = r * b.angular_momentum;
        }
    }
}

}  // namespace engine
