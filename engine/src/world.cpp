// engine/src/world.cpp -- the fixed step and the collision pipeline.
// Bodies are processed in id order and pairs come out of the broad phase sorted, so every step
// does the same floating-point operations in the same order: runs are bit-identical.
#include "engine/world.h"

#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "collision/narrow_phase.h"

namespace engine {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

std::unique_ptr<collision::BroadPhase> makeBroadPhase(const std::string& name) {
    const collision::BroadPhaseEntry* entry = collision::findBroadPhase(name);
    if (entry == nullptr) {
        throw std::invalid_argument("unknown broad phase '" + name +
                                    "' (expected one of: " + collision::broadPhaseNames() + ")");
    }
    return entry->create();
}

// The rotation by angle |w| dt about w (w != 0).
Quat rotationBy(const Vec3& w, Real dt) {
    const Real n = w.norm();
    if (!(n > 0)) return Quat::Identity();
    return Quat(Eigen::AngleAxis<Real>(n * dt, w / n));
}

}  // namespace

namespace {

struct IntegratorEntry {
    Integrator integrator;
    std::string_view name;
};

constexpr IntegratorEntry kIntegrators[] = {
    {Integrator::ExplicitEuler, "explicit_euler"},
    {Integrator::SemiImplicitEuler, "semi_implicit_euler"},
    {Integrator::Rk4, "rk4"},
};

}  // namespace

std::string_view integratorName(Integrator integrator) {
    for (const IntegratorEntry& e : kIntegrators) {
        if (e.integrator == integrator) return e.name;
    }
    return "semi_implicit_euler";
}

bool findIntegrator(std::string_view name, Integrator& out) {
    for (const IntegratorEntry& e : kIntegrators) {
        if (e.name == name) {
            out = e.integrator;
            return true;
        }
    }
    return false;
}

std::string integratorNames() {
    std::string out;
    for (const IntegratorEntry& e : kIntegrators) {
        if (!out.empty()) out += ", ";
        out += e.name;
    }
    return out;
}

std::string_view bodyStateName(BodyState state) {
    switch (state) {
        case BodyState::Apart: return "apart";
        case BodyState::Flagged: return "flagged";
        case BodyState::Colliding: return "colliding";
    }
    return "apart";
}

World::World(WorldSettings settings)
    : settings_(std::move(settings)), broad_phase_(makeBroadPhase(settings_.broad_phase)) {}

World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

BodyId World::addBody(Body body) {
    const BodyId id = static_cast<BodyId>(bodies_.size());
    bodies_.push_back(std::move(body));
    states_.push_back(BodyState::Apart);
    const Body& b = bodies_.back();
    const Pose pose = b.pose();
    volumes_.push_back(collision::ProxyVolumes{
        collision::computeWorldAabb(b.shape, pose),
        collision::transformSphere(b.local_bounds.sphere, pose),
        collision::transformObb(b.local_bounds.obb, pose)});
    if (proxies_inserted_) broad_phase_->insert(id, volumes_.back());
    return id;
}

void World::setBroadPhase(const std::string& name) {
    broad_phase_ = makeBroadPhase(name);
    settings_.broad_phase = name;
    proxies_inserted_ = false;
}

void World::integrate(Real dt) {
    switch (settings_.integrator) {
        case Integrator::ExplicitEuler: integrateExplicitEuler(dt); break;
        case Integrator::SemiImplicitEuler: integrateSemiImplicitEuler(dt); break;
        case Integrator::Rk4: integrateRk4(dt); break;
    }
}

void World::integrateExplicitEuler(Real dt) {
    // Forward Euler on every component, all derivatives taken at the start of the step:
    // x_{n+1} = x_n + v_n dt, P_{n+1} = P_n + m g dt, q_{n+1} = q_n + 1/2 (0, w_n) q_n dt
    // (Baraff, "Physically Based Modeling", SIGGRAPH course notes, rigid body dynamics §2.9),
    // then q normalised. First order: under gravity x_n = x_0 + v_0 t + g dt^2 n (n - 1) / 2, and
    // the rotational energy of an asymmetric body drifts by O(dt) per unit time.
    for (Body& b : bodies_) {
        b.position += b.velocity() * dt;
        b.linear_momentum += b.mass * settings_.gravity * dt;
        const Vec3 w = b.angularVelocity();
        if (!(w.squaredNorm() > 0)) continue;
        const Quat dq = Quat(0, w.x(), w.y(), w.z()) * b.orientation;
        b.orientation.coeffs() += (Real(0.5) * dt) * dq.coeffs();
        b.orientation.normalize();
    }
}

void World::integrateSemiImplicitEuler(Real dt) {
    // Semi-implicit (symplectic) Euler: momentum first, then position with the new velocity.
    // No torques act, so L stays constant. The orientation turns by an exact rotation (unit q up
    // to rounding) about the angular velocity taken at the half-step orientation (explicit
    // midpoint): w depends on R through w = R I^-1 R^T L, and sampling it at the start of the
    // step alone drifts the rotational energy of asymmetric bodies at first order in dt.
    for (Body& b : bodies_) {
        b.linear_momentum += b.mass * settings_.gravity * dt;
        b.position += b.velocity() * dt;
        const Vec3 w0 = b.angularVelocity();
        if (!(w0.squaredNorm() > 0)) continue;
        const Quat half = rotationBy(w0, dt / 2) * b.orientation;
        const Mat3 r = half.toRotationMatrix();
        const Vec3 w_half = r * (b.inv_inertia_body * (r.transpose() * b.angular_momentum));
        b.orientation = (rotationBy(w_half, dt) * b.orientation).normalized();
    }
}

void World::integrateRk4(Real dt) {
    // Classical Runge-Kutta 4 on y = (x, P, q, L) with y' = (P/m, m g, 1/2 (0, w(q)) q, 0), where
    // w(q) = R(q) I^-1 R(q)^T L and R(q) is the rotation of q normalised (the stages leave the
    // unit sphere by O(dt^5)); q is normalised once after the step. Gravity is constant, so x is
    // exact to rounding (RK4 integrates the quadratic exactly); rotation error is O(dt^4) per
    // unit time.
    for (Body& b : bodies_) {
        const Vec3 v0 = b.velocity();
        const Vec3 a = settings_.gravity;
        // x'' = g is constant: the four stages give x + v dt + g dt^2 / 2 exactly.
        b.position += v0 * dt + a * (dt * dt / 2);
        b.linear_momentum += b.mass * a * dt;
        if (!(b.angular_momentum.squaredNorm() > 0)) continue;
        const Vec3 l = b.angular_momentum;
        const Mat3& inv_i = b.inv_inertia_body;
        auto qdot = [&l, &inv_i](const Quat& q) {
            const Mat3 r = q.normalized().toRotationMatrix();
            const Vec3 w = r * (inv_i * (r.transpose() * l));
            Quat d = Quat(0, w.x(), w.y(), w.z()) * q;
            d.coeffs() *= Real(0.5);
            return d;
        };
        auto plus = [](const Quat& q, const Quat& d, Real h) {
            return Quat(q.coeffs() + h * d.coeffs());
        };
        const Quat q0 = b.orientation;
        const Quat k1 = qdot(q0);
        const Quat k2 = qdot(plus(q0, k1, dt / 2));
        const Quat k3 = qdot(plus(q0, k2, dt / 2));
        const Quat k4 = qdot(plus(q0, k3, dt));
        const Eigen::Matrix<Real, 4, 1> sum =
            k1.coeffs() + 2 * k2.coeffs() + 2 * k3.coeffs() + k4.coeffs();
        b.orientation = Quat(q0.coeffs() + (dt / 6) * sum).normalized();
    }
}

void World::reflectOffBounds() {
    // The coursework's "reflect objects off the edge of the scene": a body whose exact world AABB
    // crosses a face of the bounds while moving outward has that velocity component negated.
    // Kinetic energy is unchanged by the flip.
    // Runs after updateVolumes: the flip changes momenta only, so the AABBs stay valid.
    const collision::Aabb& bounds = settings_.bounds;
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
        Body& b = bodies_[i];
        const collision::Aabb& box = volumes_[i].aabb;
        for (int k = 0; k < 3; ++k) {
            const Real p = b.linear_momentum[k];
            if ((box.min[k] < bounds.min[k] && p < 0) || (box.max[k] > bounds.max[k] && p > 0)) {
                b.linear_momentum[k] = -p;
            }
        }
    }
}

void World::updateVolumes() {
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
        const Body& b = bodies_[i];
        const Pose pose = b.pose();
        collision::ProxyVolumes& v = volumes_[i];
        v.aabb = collision::computeWorldAabb(b.shape, pose);
        v.sphere = collision::transformSphere(b.local_bounds.sphere, pose);
        v.obb = collision::transformObb(b.local_bounds.obb, pose);
        const auto id = static_cast<collision::ProxyId>(i);
        if (proxies_inserted_) {
            broad_phase_->move(id, v);
        } else {
            broad_phase_->insert(id, v);
        }
    }
    proxies_inserted_ = true;
}

void World::runCollisionPipeline() {
    Clock::time_point t = Clock::now();
    stats_.broad = {};
    broad_phase_->findPairs(flagged_, stats_.broad);
    stats_.broad_phase_s = secondsSince(t);

    t = Clock::now();
    colliding_.clear();
    stats_.narrow_tests = 0;
    stats_.triangle_tests = 0;
    for (const collision::ProxyPair& pair : flagged_) {
        const Body& a = bodies_[pair.a];
        const Body& b = bodies_[pair.b];
        const collision::CollideOutput out = collision::collide(a.shape, a.pose(), b.shape, b.pose());
        ++stats_.narrow_tests;
        stats_.triangle_tests += out.triangle_tests;
        if (collision::isColliding(out.state)) colliding_.push_back(pair);
    }
    stats_.narrow_phase_s = secondsSince(t);

    std::fill(states_.begin(), states_.end(), BodyState::Apart);
    for (const collision::ProxyPair& p : flagged_) {
        states_[p.a] = std::max(states_[p.a], BodyState::Flagged);
        states_[p.b] = std::max(states_[p.b], BodyState::Flagged);
    }
    for (const collision::ProxyPair& p : colliding_) {
        states_[p.a] = BodyState::Colliding;
        states_[p.b] = BodyState::Colliding;
    }
}

void World::detect() {
    const Clock::time_point start = Clock::now();
    stats_.integrate_s = 0;
    const Clock::time_point t = Clock::now();
    updateVolumes();
    stats_.volumes_s = secondsSince(t);
    runCollisionPipeline();
    stats_.total_s = secondsSince(start);
}

void World::step() {
    const Clock::time_point start = Clock::now();
    Clock::time_point t = start;
    integrate(settings_.time_step);
    time_ += settings_.time_step;
    ++step_count_;
    stats_.integrate_s = secondsSince(t);

    t = Clock::now();
    updateVolumes();
    reflectOffBounds();
    stats_.volumes_s = secondsSince(t);
    runCollisionPipeline();
    stats_.total_s = secondsSince(start);
}

std::uint64_t World::stateHash() const {
    // FNV-1a over the exact bit patterns of the state.
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&h](const void* data, std::size_t n) {
        const auto* bytes = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < n; ++i) {
            h ^= bytes[i];
            h *= 1099511628211ull;
        }
    };
    auto mixVec = [&mix](const Vec3& v) { mix(v.data(), sizeof(Real) * 3); };
    mix(&time_, sizeof(time_));
    for (const Body& b : bodies_) {
        mixVec(b.position);
        mix(b.orientation.coeffs().data(), sizeof(Real) * 4);
        mixVec(b.linear_momentum);
        mixVec(b.angular_momentum);
    }
    for (BodyState s : states_) mix(&s, sizeof(s));
    return h;
}

}  // namespace engine
