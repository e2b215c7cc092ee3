// engine/src/world.cpp -- the fixed step: integrators, bounds reflection, the collision pipeline
// and the contact solver's pairs (the continuous stage is world_continuous.cpp, the contact
// detail and debug drawing world_contacts.cpp, deforming and self-colliding meshes
// world_deform.cpp).
// Bodies are processed in id order and pairs come out of the broad phase in an order fixed by the
// calls made to it (sorted by default; settings().pair_order), the contact solver and the CCD
// stage take theirs from instances of the same broad phase over their own boxes, sorted
// (box_pair_finder.h; the CCD stage sorts its events by
// (t, a, b)), so every step does the same floating-point operations in the same order: runs are
// bit-identical, and the bodies' motion is the same in either pair order.
#include "engine/world.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "collision/assert.h"
#include "collision/bvh/bvh.h"
#include "collision/ccd/ccd.h"
#include "collision/narrowphase/narrow_phase.h"
#include "box_pair_finder.h"
#include "response_stage.h"
#include "stage_clock.h"
#include "world_records.h"

namespace engine {

namespace {

using Clock = StageClock;

std::unique_ptr<collision::BroadPhase> makeBroadPhase(const std::string& name,
                                                      collision::PairOrder order) {
    const collision::BroadPhaseEntry* entry = collision::findBroadPhase(name);
    if (entry == nullptr) {
        throw std::invalid_argument("unknown broad phase '" + name +
                                    "' (expected one of: " + collision::broadPhaseNames() + ")");
    }
    std::unique_ptr<collision::BroadPhase> made = entry->create();
    made->setPairOrder(order);
    return made;
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

struct CcdEntry {
    CcdMethod method;
    std::string_view name;
};

constexpr CcdEntry kCcdMethods[] = {
    {CcdMethod::Off, "off"},
    {CcdMethod::ConservativeAdvancement, "conservative_advancement"},
};

struct ResponseEntry {
    Response response;
    std::string_view name;
};

constexpr ResponseEntry kResponses[] = {{Response::None, "none"}, {Response::Impulse, "impulse"}};

}  // namespace

std::string_view responseName(Response response) {
    for (const ResponseEntry& e : kResponses) {
        if (e.response == response) return e.name;
    }
    return "none";
}

bool findResponse(std::string_view name, Response& out) {
    for (const ResponseEntry& e : kResponses) {
        if (e.name == name) {
            out = e.response;
            return true;
        }
    }
    return false;
}

std::string_view ccdMethodName(CcdMethod method) {
    for (const CcdEntry& e : kCcdMethods) {
        if (e.method == method) return e.name;
    }
    return "off";
}

bool findCcdMethod(std::string_view name, CcdMethod& out) {
    for (const CcdEntry& e : kCcdMethods) {
        if (e.name == name) {
            out = e.method;
            return true;
        }
    }
    return false;
}

std::string_view ccdSpheresName(CcdSpheres method) {
    return method == CcdSpheres::Exact ? "exact" : "advancement";
}

bool findCcdSpheres(std::string_view name, CcdSpheres& out) {
    if (name == "advancement") {
        out = CcdSpheres::Advancement;
        return true;
    }
    if (name == "exact") {
        out = CcdSpheres::Exact;
        return true;
    }
    return false;
}

std::string ccdMethodNames() {
    std::string out;
    for (const CcdEntry& e : kCcdMethods) {
        if (!out.empty()) out += ", ";
        out += e.name;
    }
    return out;
}

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
        case BodyState::Apart:
            return "apart";
        case BodyState::Flagged:
            return "flagged";
        case BodyState::Colliding:
            return "colliding";
    }
    return "apart";
}

World::World(WorldSettings settings)
    : settings_(std::move(settings)),
      broad_phase_(makeBroadPhase(settings_.broad_phase, settings_.pair_order)) {
    if (settings_.ccd != CcdMethod::Off) {
        ccd_finder_ = std::make_unique<BoxPairFinder>(settings_.broad_phase);
    }
    if (settings_.response == Response::Impulse) {
        response_ = std::make_unique<ResponseStage>(settings_);
    }
}

World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;
World::World(const World&) = default;

std::span<const collision::ProxyPair> World::pushedPairs() const {
    return response_ ? response_->pushedPairs() : std::span<const collision::ProxyPair>{};
}
World& World::operator=(const World&) = default;

Real WorldSnapshot::time() const { return world_ ? world_->time() : Real(0); }
std::int64_t WorldSnapshot::steps() const { return world_ ? world_->stepCount() : 0; }

WorldSnapshot World::snapshot() const {
    auto copy = std::shared_ptr<World>(new World(*this));
    copy->ownDeformingGeometry();
    WorldSnapshot out;
    out.world_ = std::move(copy);
    return out;
}

void World::restore(const WorldSnapshot& snapshot) {
    if (snapshot.empty()) throw std::invalid_argument("restore: the snapshot is empty");
    *this = *snapshot.world_;
    ownDeformingGeometry();
}

void World::ownDeformingGeometry() {
    for (DeformingMesh& d : deforming_) {
        d.mesh = std::make_shared<collision::TriangleMesh>(*d.mesh);
        d.bvh = std::shared_ptr<collision::MeshBvh>(d.bvh->clone());
        Body& body = bodies_[static_cast<std::size_t>(d.body)];
        body.shape.mesh = d.mesh;
        body.shape.bvh = d.bvh;
    }
}

BodyId World::addBody(Body body) {
    const BodyId id = static_cast<BodyId>(bodies_.size());
    bodies_.push_back(std::move(body));
    states_.push_back(BodyState::Apart);
    self_pairs_.emplace_back();
    const Body& added = bodies_.back();
    if (added.deform) addDeforming(id);
    const Body& b = bodies_.back();
    const Pose pose = b.pose();
    volumes_.push_back(
        collision::ProxyVolumes{collision::computeWorldAabb(b.shape, pose),
                                collision::transformSphere(b.local_bounds.sphere, pose),
                                collision::transformObb(b.local_bounds.obb, pose)});
    if (proxies_inserted_) broad_phase_->insert(id, volumes_.back());
    return id;
}

void World::setBroadPhase(const std::string& name) {
    const bool detected = proxies_inserted_;
    broad_phase_ = makeBroadPhase(name, settings_.pair_order);
    settings_.broad_phase = name;
    proxies_inserted_ = false;
    if (ccd_finder_) ccd_finder_->reset(name);
    if (response_) response_->reset(name);
    // The pairs, states and structure of the current state are the new broad phase's at once.
    if (detected) detect();
}

void World::integrate(Real dt, const Vec3& gravity) {
    switch (settings_.integrator) {
        case Integrator::ExplicitEuler:
            integrateExplicitEuler(dt, gravity);
            break;
        case Integrator::SemiImplicitEuler:
            integrateSemiImplicitEuler(dt, gravity);
            break;
        case Integrator::Rk4:
            integrateRk4(dt, gravity);
            break;
    }
}

void World::integrateExplicitEuler(Real dt, const Vec3& gravity) {
    // Forward Euler on every component, all derivatives taken at the start of the step:
    // x_{n+1} = x_n + v_n dt, P_{n+1} = P_n + m g dt, q_{n+1} = q_n + 1/2 (0, w_n) q_n dt
    // (Baraff, "Physically Based Modeling", SIGGRAPH course notes, rigid body dynamics §2.9),
    // then q normalised. First order: under gravity x_n = x_0 + v_0 t + g dt^2 n (n - 1) / 2, and
    // the rotational energy of an asymmetric body drifts by O(dt) per unit time.
    for (Body& b : bodies_) {
        if (b.is_static) continue;
        b.position += b.velocity() * dt;
        b.linear_momentum += b.mass * gravity * dt;
        const Vec3 w = b.angularVelocity();
        if (!(w.squaredNorm() > 0)) continue;
        const Quat dq = Quat(0, w.x(), w.y(), w.z()) * b.orientation;
        b.orientation.coeffs() += (Real(0.5) * dt) * dq.coeffs();
        b.orientation.normalize();
    }
}

void World::integrateSemiImplicitEuler(Real dt, const Vec3& gravity) {
    // Semi-implicit (symplectic) Euler for translation: momentum first, then position with the
    // new velocity. Rotation: no torque acts, so L (world) is constant, and the free rigid body
    // H = sum_k L_k^2 / (2 I_k) (principal frame, I_0 <= I_1 <= I_2) is split around the middle
    // moment: H = |L|^2 / (2 I_1) + sum_{k = 0, 2} (1/I_k - 1/I_1) L_k^2 / 2 (Touma & Wisdom
    // 1994; Dullweber, Leimkuhler, McLachlan 1997, J. Chem. Phys. 107, "symmetric splitting").
    // Each part is an exact rotation: the first about L itself (it commutes with the others),
    // part k about principal axis k by (1/I_k - 1/I_1) L_k h. Strang composition, the stiffest
    // axis (smallest moment) in the middle: second order, symplectic, |L| exact, energy error
    // bounded (no drift), exact for symmetric bodies; and stable for thin bodies spinning about
    // their long axis, where explicit updates of w = R I^-1 R^T L blow up (the gyroscopic term).
    const bool record_sweeps = settings_.ccd != CcdMethod::Off;
    if (record_sweeps) {
        step_rotation_.assign(bodies_.size(), Vec3::Zero());
        step_spin_.assign(bodies_.size(), Vec3::Zero());
    }
    for (Body& b : bodies_) {
        if (b.is_static) continue;
        b.linear_momentum += b.mass * gravity * dt;
        b.position += b.velocity() * dt;
        const Real l_norm = b.angular_momentum.norm();
        if (!(l_norm > 0)) continue;
        Quat qp = b.orientation * b.principal_frame;   // principal frame -> world
        Vec3 l = qp.conjugate() * b.angular_momentum;  // L in the principal frame
        const Vec3& moments = b.principal_moments;
        auto flow = [&qp, &l, &moments](int k, Real h) {
            const Real phi = l[k] * h * (1 / moments[k] - 1 / moments[1]);
            const Quat r(Eigen::AngleAxis<Real>(phi, Vec3::Unit(k)));
            qp = qp * r;
            l = r.conjugate() * l;
        };
        const Quat qp0 = qp;
        flow(2, dt / 2);
        flow(0, dt);
        flow(2, dt / 2);
        // The isotropic part: a turn about L (l is unchanged by it), i.e. about L in the world.
        const Real iso = l_norm * dt / moments[1];
        qp = qp * Quat(Eigen::AngleAxis<Real>(iso, l / l.norm()));
        b.orientation = (qp * b.principal_frame.conjugate()).normalized();
        if (record_sweeps) {
            // q1 = R(L, iso) q0 S with S the body-frame part of the flows: the CCD sweep
            // (collision::Sweep: world rotation and body spin), exact for symmetric bodies.
            const std::size_t i = static_cast<std::size_t>(&b - bodies_.data());
            const Quat body_part = b.principal_frame * (qp0.conjugate() * qp) *
                                   Quat(Eigen::AngleAxis<Real>(-iso, l / l.norm())) *
                                   b.principal_frame.conjugate();
            const Eigen::AngleAxis<Real> aa(body_part);
            step_rotation_[i] = b.angular_momentum * (iso / l_norm);
            step_spin_[i] = aa.axis() * aa.angle();
        }
    }
}

void World::integrateRk4(Real dt, const Vec3& gravity) {
    // Classical Runge-Kutta 4 on y = (x, P, q, L) with y' = (P/m, m g, 1/2 (0, w(q)) q, 0), where
    // w(q) = R(q) I^-1 R(q)^T L and R(q) is the rotation of q normalised (the stages leave the
    // unit sphere by O(dt^5)); q is normalised once after the step. Gravity is constant, so x is
    // exact to rounding (RK4 integrates the quadratic exactly); rotation error is O(dt^4) per
    // unit time.
    for (Body& b : bodies_) {
        if (b.is_static) continue;
        const Vec3 v0 = b.velocity();
        const Vec3 a = gravity;
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
    // The coursework's "reflect objects off the edge of the scene" (response: none): a body
    // whose exact world AABB crosses a face of the bounds while moving outward has that velocity
    // component negated. Kinetic energy is unchanged by the flip. With response: impulse the
    // faces are walls of the contact solver instead (restitution, friction, resting contact),
    // and only the fold below remains, as the last resort for a body that went through one.
    // Runs after updateVolumes: the flip changes momenta only, so the AABBs stay valid.
    // A body fast enough to carry its centre of mass past a face within one step (a 20 m world
    // crossed at 1e4 m/s) would leave for good, flipping back and forth outside. Its centre is
    // folded back instead, mirrored across the faces as many times as it crossed them (a
    // triangle wave over the bounds), with the velocity flipped once per crossing: the path a
    // perfectly elastic bounce would have taken, and the centre always ends inside. Bodies
    // whose centre stays inside (every moderate speed) take the plain flip only.
    const collision::Aabb& bounds = settings_.bounds;
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
        Body& b = bodies_[i];
        bool folded = false;
        for (int k = 0; k < 3; ++k) {
            const Real lo = bounds.min[k];
            const Real width = bounds.max[k] - lo;
            const Real x = b.position[k];
            if (b.is_static || (x >= lo && x <= bounds.max[k])) continue;
            // u in [0, 2 width): the position on the unfolded path, modulo one round trip.
            Real u = std::fmod(x - lo, 2 * width);
            if (u < 0) u += 2 * width;
            // The fold maps the unfolded straight path onto the bounced one: in the mirrored
            // half (u > width) positions and velocities are mirrored, in the other they are not.
            const bool mirrored = u > width;
            b.position[k] = lo + (mirrored ? 2 * width - u : u);
            if (mirrored) b.linear_momentum[k] = -b.linear_momentum[k];
            folded = true;
        }
        if (folded) updateVolume(i);
        if (response_) continue;
        const collision::Aabb& box = volumes_[i].aabb;
        for (int k = 0; k < 3; ++k) {
            const Real p = b.linear_momentum[k];
            if ((box.min[k] < bounds.min[k] && p < 0) || (box.max[k] > bounds.max[k] && p > 0)) {
                b.linear_momentum[k] = -p;
            }
        }
    }
}

void World::updateVolume(std::size_t i) {
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

void World::updateVolumes() {
    for (std::size_t i = 0; i < bodies_.size(); ++i) updateVolume(i);
    proxies_inserted_ = true;
}

void World::runCollisionPipeline() {
    details_.clear();  // the contact details of the previous state
    convex_details_ = mesh_details_ = false;
    Clock::time_point t = Clock::now();
    stats_.broad = {};
    broad_phase_->findPairs(flagged_, stats_.broad);
    if (!chains_.empty()) dropExcludedPairs(flagged_);
    stats_.broad_phase_s = secondsSince(t);
    if (flagged_.size() > settings_.max_candidate_pairs) {
        throw SimulationError(std::to_string(flagged_.size()) + " candidate pairs after step " +
                              std::to_string(step_count_) + ", more than the limit of " +
                              std::to_string(settings_.max_candidate_pairs) +
                              " a step may flag (the bodies' volumes overlap en masse; the "
                              "narrow phase would test every pair)");
    }

    t = Clock::now();
    colliding_.clear();
    stats_.narrow_tests = 0;
    stats_.triangle_tests = 0;
    stats_.bv_tests = 0;
    for (const collision::ProxyPair& pair : flagged_) {
        const Body& a = bodies_[pair.a];
        const Body& b = bodies_[pair.b];
        const collision::CollideOutput out =
            collision::collide(a.shape, a.pose(), b.shape, b.pose());
        ++stats_.narrow_tests;
        stats_.triangle_tests += out.triangle_tests;
        stats_.bv_tests += out.bv_tests;
        if (collision::isColliding(out.state)) colliding_.push_back(pair);
    }
    findSelfPairs();
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
    const bool ccd = settings_.ccd != CcdMethod::Off;
    if (ccd) {
        step_start_.resize(bodies_.size());
        for (std::size_t i = 0; i < bodies_.size(); ++i) step_start_[i] = bodies_[i].pose();
    }
    const Real dt = settings_.time_step;
    if (response_) {
        // Impulse response: gravity as a velocity kick, then the contact solver on the pairs
        // whose AABBs, grown by the speculative margin, overlap (touching, penetrating or close),
        // then the integrator moves the bodies with the solved velocities (no further gravity).
        response_->solve(bodies_, volumes_, settings_, dt);
        stats_.response_s = secondsSince(t);
        stats_.contact_points = response_->pointCount();
        stats_.response_broad = response_->pairCounters();
        stats_.response_pairs = response_->pairCount();
        t = Clock::now();
        integrate(dt, Vec3::Zero());
    } else {
        integrate(dt, settings_.gravity);
    }
    time_ += dt;
    ++step_count_;
    if (!chains_.empty()) moveChains();
    stats_.integrate_s = secondsSince(t);

    if (ccd) {
        t = Clock::now();
        checkFiniteState();  // the swept bounds go to a broad phase: finite only
        resolveContinuous();
        stats_.ccd_s = secondsSince(t);
    }
    if (response_) response_->correctPositions(bodies_, dt);  // split-impulse correction

    checkFiniteState();
    stats_.refit_nodes = 0;
    stats_.refit_s = 0;
    stats_.rebuilds = 0;
    for (DeformingMesh& d : deforming_) deformBody(d);
    t = Clock::now();
    updateVolumes();
    reflectOffBounds();
    stats_.volumes_s = secondsSince(t);
    runCollisionPipeline();
    stats_.total_s = secondsSince(start);
}

void World::checkFiniteState() const {
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
        const Body& b = bodies_[i];
        const char* quantity = !b.position.allFinite()               ? "position"
                               : !b.orientation.coeffs().allFinite() ? "orientation"
                               : !b.linear_momentum.allFinite()      ? "linear momentum"
                               : !b.angular_momentum.allFinite()     ? "angular momentum"
                                                                     : nullptr;
        if (quantity == nullptr) continue;
        throw SimulationError("body '" + b.name + "' (bodies[" + std::to_string(i) +
                              "]): " + quantity + " is not finite after step " +
                              std::to_string(step_count_) +
                              " (the scene's speeds, spins or forces exceed what double "
                              "precision can integrate)");
    }
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
