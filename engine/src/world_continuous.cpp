// engine/src/world_continuous.cpp -- the World's continuous stage (world.ccd:
// conservative_advancement): sweeps of every body over the step, the pairs whose swept bounds
// overlap, a time of impact per pair, and each body stopped at its earliest one with an impulse.
#include <algorithm>
#include <cmath>

#include "collision/bvh/bvh.h"
#include "collision/ccd/ccd.h"
#include "box_pair_finder.h"
#include "engine/world.h"
#include "toi_query.h"
#include "world_records.h"

namespace engine {

namespace {

// Iteration cap of one time-of-impact query (Failed -> the pair is stopped at the safe time).
constexpr int kCcdMaxIterations = 64;
// Restitution of the impulse that resolves a time of impact while `response` is none: elastic
// and frictionless, like the reflection off the bounds (kinetic energy kept). With response
// impulse the pair's restitution (the larger of the two) is used instead.
constexpr Real kCcdRestitution = 1;

// Velocity of the material point at world `p` of body `b` placed at `pose` (m/s).
Vec3 pointVelocity(const Body& b, const Pose& pose, const Vec3& p) {
    const Mat3 r = pose.rotation();
    const Vec3 w = r * (b.inv_inertia_body * (r.transpose() * b.angular_momentum));
    return b.velocity() + w.cross(p - pose.position);
}

// Rotation vector (axis * angle, angle in [0, pi]) of the rotation q1 q0^-1.
Vec3 rotationBetween(const Quat& q0, const Quat& q1) {
    const Eigen::AngleAxis<Real> aa(q1 * q0.conjugate());
    return aa.axis() * aa.angle();
}

}  // namespace

// The continuous stage (ccd: conservative_advancement; sphere pairs by the exact quadratic
// root with ccd_spheres: exact). After integration every body has a sweep from its pose at the
// start of the step to its integrated pose: linear in position; for semi-implicit Euler the
// integrator's rotation as a world turn about L and a body-frame spin (exact for symmetric bodies,
// so a pose stopped mid-step keeps the energy), for the other integrators the constant-axis chord
// from start to end.
// 1. Candidate pairs: swept bounds (AABB of the centre's segment grown by the bounding
//    radius about the centre) overlap, at least one body moves. Found by an instance of the
//    scene's broad phase over the swept bounds (box_pair_finder.h), pairs sorted.
// 2. timeOfImpact per pair (never later than first contact, target gap kept). A pair that
//    starts within the target gap is asked again with half its present gap as the target.
//    A pair already overlapped at t = 0 is left to the discrete pipeline, and so is a pair
//    that still hits at t = 0 while its witness points separate (stopping it would freeze
//    it).
// 3. Each body is stopped at its earliest accepted time of impact (the rest of its step is
//    dropped), then each event that is the earliest for one of its moving bodies gets an
//    impulse (restitution kCcdRestitution with response none, else the pair's;
//    frictionless) at the witness midpoint, in (t, a, b) order.
// Deforming mesh bodies: the stage sweeps the shape of the step's start (the world deforms
// after it) and each query bounds how far the surface moves from it over the step
// (deformSpeedBound x time step, ToiQuery::deform_speed_a/_b; the swept bounds grow by as much),
// so no pair overlaps at any time before its stop, deforming surface included. The deformation
// is prescribed and goes on after a stop; the discrete pipeline sees what it presses into.
// Chain links (world_chains.cpp) take part with their conservative swept bounds
// (collision::linkSweptBounds), parent-child pairs dropped unless the chain collides adjacent
// links; their pairs go through collision::timeOfImpactArticulated. A link is infinitely heavy
// and moves with its chain: its impulse share is nil and its prescribed velocity enters the
// relative velocity; on_impact: stop halts the whole chain at its earliest event.
// Limitation: one round. A body stopped early is not re-tested against the bodies whose
// sweeps it no longer blocks, and a third body's sweep is not re-tested against the stopped
// pose (the discrete pipeline still sees any overlap that results).
void World::resolveContinuous() {
    buildSweeps();
    ccd_finder_->find(
        swept_boxes_,
        [this](BodyId i, BodyId j) {
            return (swept_[i].moving || swept_[j].moving) && pairAllowed(i, j);
        },
        ccd_pairs_);
    stats_.ccd_broad = ccd_finder_->counters();
    stats_.ccd_pairs = static_cast<std::int64_t>(ccd_pairs_.size());
    queryTimesOfImpact();
    stopAtImpacts();
    applyImpactImpulses();
}

// Every body's sweep from its pose at the start of the step to its integrated pose, and its
// swept bounds (also in `swept_boxes_`, for the pair finder).
void World::buildSweeps() {
    const std::size_t n = bodies_.size();
    swept_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Body& b = bodies_[i];
        SweptBody& s = swept_[i];
        s.sweep.start = step_start_[i];
        s.sweep.translation = b.position - step_start_[i].position;
        if (settings_.integrator == Integrator::SemiImplicitEuler) {
            s.sweep.rotation = step_rotation_[i];  // the integrator's own rotation path
            s.sweep.spin = step_spin_[i];
        } else {
            s.sweep.rotation = rotationBetween(step_start_[i].orientation, b.orientation);
            s.sweep.spin = Vec3::Zero();
        }
        s.radius = b.local_bounds.sphere.center.norm() + b.local_bounds.sphere.radius;
        s.box.min = step_start_[i].position.cwiseMin(b.position) - Vec3::Constant(s.radius);
        s.box.max = step_start_[i].position.cwiseMax(b.position) + Vec3::Constant(s.radius);
        s.clamp_t = 1;
        s.deform_speed = 0;
        s.moving =
            !b.is_static && (s.sweep.translation.squaredNorm() > 0 ||
                             s.sweep.rotation.squaredNorm() > 0 || s.sweep.spin.squaredNorm() > 0);
        if (b.kinematic) sweepLink(i, s);
    }
    // A deforming body's surface also moves in its own frame, up to deform_speed over the step:
    // its swept bounds grow by that much.
    for (const DeformingMesh& d : deforming_) {
        SweptBody& s = swept_[static_cast<std::size_t>(d.body)];
        s.deform_speed = d.speed_bound * settings_.time_step;
        s.box.min -= Vec3::Constant(s.deform_speed);
        s.box.max += Vec3::Constant(s.deform_speed);
    }
    swept_boxes_.resize(n);
    for (std::size_t i = 0; i < n; ++i) swept_boxes_[i] = swept_[i].box;
}

ToiEvent World::impactEvent(const collision::ProxyPair& pair, const collision::ToiOutput& out,
                            const Pose& pose_a, const Pose& pose_b) {
    ToiEvent e;
    e.a = pair.a;
    e.b = pair.b;
    e.t = out.t;
    e.pose_a = pose_a;
    e.pose_b = pose_b;
    e.failed = out.state == collision::CcdState::Failed;
    e.normal = out.normal;
    if (!(e.normal.squaredNorm() > 0)) {
        // Failed before any distance: the line of centres (or +x) is the best guess.
        const Vec3 d = e.pose_b.position - e.pose_a.position;
        const Real len = d.norm();
        e.normal = len > 0 ? Vec3(d / len) : Vec3(Vec3::UnitX());
        e.point = (e.pose_a.position + e.pose_b.position) / 2;
    } else {
        e.point = (out.point_a + out.point_b) / 2;
    }
    return e;
}

// A time of impact per candidate pair; the events kept, sorted by (t, a, b).
void World::queryTimesOfImpact() {
    toi_events_.clear();
    stats_.toi_queries = 0;
    stats_.toi_iterations = 0;
    for (const collision::ProxyPair& pair : ccd_pairs_) {
        const Body& a = bodies_[pair.a];
        const Body& b = bodies_[pair.b];
        if (a.kinematic || b.kinematic) {
            queryLinkImpact(pair);  // the articulated query (world_chains.cpp)
            continue;
        }
        collision::ToiInput in;
        in.a = &a.shape;
        in.b = &b.shape;
        in.sweep_a = swept_[pair.a].sweep;
        in.sweep_b = swept_[pair.b].sweep;
        // Target gap (settings_.ccd_target_gap of the smaller bounding radius of the pair): a
        // pair stopped at its time of impact is left this far apart, plus the query's tolerance
        // (settings_.ccd_tolerance of the smaller shape radius), so the next step starts
        // separated.
        in.target_gap =
            settings_.ccd_target_gap * std::min(swept_[pair.a].radius, swept_[pair.b].radius);
        in.relative_tolerance = settings_.ccd_tolerance;
        in.max_iterations = kCcdMaxIterations;
        // A deforming body's shape is its shape at the start of the step (deformed after this
        // stage); the query bounds how far its surface moves from it in the step.
        in.deform_speed_a = swept_[pair.a].deform_speed;
        in.deform_speed_b = swept_[pair.b].deform_speed;
        // Two meshes with OBB trees (obb, or the binary tree inside obb4: obbTreeOf): their
        // surfaces, triangle pair by triangle pair under the continuous OBB test's culling (a
        // ring may pass around a rod). Any other pair: the convex shapes, a mesh standing for its
        // convex hull (conservative: may stop early); so is a deforming mesh, whose tree's
        // culling assumes a rigid shape.
        const bool rigid = in.deform_speed_a == 0 && in.deform_speed_b == 0;
        const collision::Bvh<collision::Obb>* tree_a =
            rigid && a.shape.bvh != nullptr ? collision::obbTreeOf(*a.shape.bvh) : nullptr;
        const collision::Bvh<collision::Obb>* tree_b =
            rigid && b.shape.bvh != nullptr ? collision::obbTreeOf(*b.shape.bvh) : nullptr;
        // Two spheres with ccd_spheres: exact: the closed-form root of |d0 + t dv| = ra + rb +
        // gap, exact for the sweeps' linear motion of the centres (collision/ccd/ccd.h).
        const bool exact_spheres = settings_.ccd_spheres == CcdSpheres::Exact &&
                                   a.shape.type == collision::ShapeType::Sphere &&
                                   b.shape.type == collision::ShapeType::Sphere;
        auto query = [&]() {
            if (exact_spheres) return collision::timeOfImpactSphereSweeps(in);
            if (tree_a == nullptr || tree_b == nullptr) return collision::timeOfImpact(in);
            collision::MeshToiInput mi;
            static_cast<collision::ToiQuery&>(mi) = in;
            mi.a = tree_a;
            mi.b = tree_b;
            return collision::timeOfImpactMeshes(mi).toi;
        };
        const collision::ToiOutput out = askTimeOfImpact(in, stats_, query);
        if (out.state != collision::CcdState::Hit && out.state != collision::CcdState::Failed) {
            continue;
        }
        const ToiEvent e = impactEvent(pair, out, in.sweep_a.at(out.t), in.sweep_b.at(out.t));
        const Real approach =
            (pointVelocity(b, e.pose_b, e.point) - pointVelocity(a, e.pose_a, e.point))
                .dot(e.normal);
        if (e.t == 0 && !(approach < 0)) continue;
        toi_events_.push_back(e);
    }
    std::sort(toi_events_.begin(), toi_events_.end(), [](const ToiEvent& x, const ToiEvent& y) {
        return x.t < y.t || (x.t == y.t && (x.a < y.a || (x.a == y.a && x.b < y.b)));
    });
}

// Each moving body stopped at its earliest accepted time of impact.
void World::stopAtImpacts() {
    // Chains first: a halted chain's later events did not happen (world_chains.cpp).
    if (!chains_.empty()) stopChainsAtImpacts();
    const std::size_t n = bodies_.size();
    for (const ToiEvent& e : toi_events_) {
        swept_[e.a].clamp_t = std::min(swept_[e.a].clamp_t, e.t);
        swept_[e.b].clamp_t = std::min(swept_[e.b].clamp_t, e.t);
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (swept_[i].clamp_t < 1 && swept_[i].moving && !bodies_[i].kinematic) {
            const Pose p = swept_[i].sweep.at(swept_[i].clamp_t);
            bodies_[i].position = p.position;
            bodies_[i].orientation = p.orientation;
        }
    }
    stats_.toi_events = static_cast<std::int64_t>(toi_events_.size());
}

// Impulse at the witness midpoint: j = -(1 + e) v_n / (1/m_a + 1/m_b
// + n.((I_a^-1 (r_a x n)) x r_a) + n.((I_b^-1 (r_b x n)) x r_b)) (Mirtich & Canny 1995;
// Baraff, SIGGRAPH course notes, "Rigid body simulation II", §8).
void World::applyImpactImpulses() {
    for (const ToiEvent& e : toi_events_) {
        // Only an event that is the earliest of one of its moving bodies gets an impulse (a
        // static body's clamp_t is just its own first event, so it does not count). If the
        // partner is a moving body stopped earlier by another event, it still takes its share
        // of the impulse at its own earlier pose: part of the one-round limitation above.
        const bool earliest_a = swept_[e.a].moving && e.t == swept_[e.a].clamp_t;
        const bool earliest_b = swept_[e.b].moving && e.t == swept_[e.b].clamp_t;
        if (!earliest_a && !earliest_b) continue;
        Body& a = bodies_[e.a];
        Body& b = bodies_[e.b];
        const Vec3 ra = e.point - a.position;
        const Vec3 rb = e.point - b.position;
        const Mat3 inv_ia = a.invInertiaWorld();
        const Mat3 inv_ib = b.invInertiaWorld();
        // A link is infinitely heavy and moves with its chain's prescribed motion.
        const Vec3 va = a.velocity() + (inv_ia * a.angular_momentum).cross(ra) +
                        linkPointVelocity(e.a, e.point, e.t);
        const Vec3 vb = b.velocity() + (inv_ib * b.angular_momentum).cross(rb) +
                        linkPointVelocity(e.b, e.point, e.t);
        const Real vn = (vb - va).dot(e.normal);
        if (!(vn < 0)) continue;
        const Real k = a.inv_mass + b.inv_mass +
                       e.normal.dot((inv_ia * ra.cross(e.normal)).cross(ra)) +
                       e.normal.dot((inv_ib * rb.cross(e.normal)).cross(rb));
        if (!(k > 0)) continue;  // two static bodies never get here (neither moves)
        const Real e_pair = settings_.response == Response::Impulse
                                ? std::max(a.restitution, b.restitution)
                                : kCcdRestitution;
        const Vec3 impulse = (-(1 + e_pair) * vn / k) * e.normal;
        if (!a.is_static) {
            a.linear_momentum -= impulse;
            a.angular_momentum -= ra.cross(impulse);
        }
        if (!b.is_static) {
            b.linear_momentum += impulse;
            b.angular_momentum += rb.cross(impulse);
        }
    }
}

}  // namespace engine
