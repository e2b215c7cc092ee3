// collision/src/ccd/advancement.cpp -- conservative advancement: the loop shared with the
// articulated query (advancement.h), and the time of impact of two convex shapes moving with
// linear translation and constant-axis rotation over one step.
// Invariant of the loop: no time in [0, t] has a gap <= target_gap (every advance is bounded by
// the gap along a fixed direction divided by the largest rate that gap can shrink at), so any t
// returned (Hit, Separated at t_max, Failed) is never later than the first contact.
#include "ccd/advancement.h"

#include <algorithm>
#include <cmath>

#include "collision/ccd/ccd.h"
#include "collision/geometry/shape.h"
#include "collision/narrowphase/narrow_phase.h"
#include "narrowphase/gjk.h"

namespace collision {

namespace {

// max over x in the shape of dir.x, for a local direction (any length).
Real supportValue(const Shape& shape, const Vec3& dir_local) {
    return supportPoint(shape, dir_local).dot(dir_local);
}

// Gap between A and B along the unit world direction n (A towards B):
// min over B of n.y - max over A of n.x. A lower bound on the distance for every n (equal to
// it for the direction of the closest points). Positions are subtracted first, so large
// offsets cost nothing but the rounding of the difference.
Real gapAlong(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, const Vec3& n) {
    const Vec3 na = pa.orientation.conjugate() * n;
    const Vec3 nb = pb.orientation.conjugate() * n;
    return n.dot(pb.position - pa.position) - supportValue(a, na) - supportValue(b, -nb);
}

// The point of the shape (at `pose`) closest to world point `q`: closed forms for spheres
// (RTCD 5.1.3 idea), boxes (RTCD 5.1.3, clamp in the local frame) and capsules (closest point on
// the segment, RTCD 5.1.2, then the sphere). Hulls and meshes: the support point towards q
// (a point of the shape, not necessarily the closest: witness quality only, not safety).
Vec3 closestPointOnShape(const Shape& shape, const Pose& pose, const Vec3& q) {
    const Vec3 p = pose.applyInverse(q);
    Vec3 local = Vec3::Zero();
    switch (shape.type) {
        case ShapeType::Sphere: {
            const Real len = p.norm();
            local = len > shape.radius ? Vec3(p * (shape.radius / len)) : p;
            break;
        }
        case ShapeType::Box:
            local = p.cwiseMax(-shape.half_extents).cwiseMin(shape.half_extents);
            break;
        case ShapeType::Capsule: {
            const Vec3 c(0, std::clamp(p.y(), -shape.half_height, shape.half_height), 0);
            const Vec3 d = p - c;
            const Real len = d.norm();
            local = len > shape.radius ? Vec3(c + d * (shape.radius / len)) : p;
            break;
        }
        case ShapeType::ConvexHull:
        case ShapeType::Mesh:
            local = supportPoint(shape, p);
            break;
    }
    return pose.apply(local);
}

// A witness on the shape's support feature along local `dir`: for boxes the centre of the
// supporting face or edge (components of dir below kSupportFeatureRelative * |dir| count as
// zero), so a face or edge contact is not reported at one arbitrary corner; other shapes:
// supportPoint.
constexpr Real kSupportFeatureRelative = Real(1e-6);
Vec3 featureCentreSupport(const Shape& shape, const Vec3& dir) {
    if (shape.type != ShapeType::Box) return supportPoint(shape, dir);
    const Real eps = kSupportFeatureRelative * dir.norm();
    Vec3 p;
    for (int k = 0; k < 3; ++k) {
        p[k] = std::abs(dir[k]) <= eps
                   ? Real(0)
                   : (dir[k] < 0 ? -shape.half_extents[k] : shape.half_extents[k]);
    }
    return p;
}

// Largest distance of the shape's points from the line through the local origin along the
// unit local direction `e` (a point at distance rho moves at |w| rho when spun about e).
Real maxDistanceFromAxis(const Shape& shape, const Vec3& e) {
    auto off = [&e](const Vec3& p) { return (p - p.dot(e) * e).norm(); };
    switch (shape.type) {
        case ShapeType::Sphere:
            return shape.radius;
        case ShapeType::Box: {
            Real m = 0;
            for (int k = 0; k < 8; ++k) {
                const Vec3 c((k & 1) ? shape.half_extents.x() : -shape.half_extents.x(),
                             (k & 2) ? shape.half_extents.y() : -shape.half_extents.y(),
                             (k & 4) ? shape.half_extents.z() : -shape.half_extents.z());
                m = std::max(m, off(c));
            }
            return m;
        }
        case ShapeType::Capsule:
            return std::max(off(Vec3(0, shape.half_height, 0)),
                            off(Vec3(0, -shape.half_height, 0))) +
                   shape.radius;
        case ShapeType::ConvexHull:
        case ShapeType::Mesh: {
            Real m = 0;
            for (const Vec3& v : shape.hull->vertices) m = std::max(m, off(v));
            return m;
        }
    }
    return 0;
}

// Witness points at the poses, for normal n: one alternating projection from each side's
// support point along the normal (exact for a vertex, sphere or capsule end against a face);
// the pair closer together wins.
void setWitnesses(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, const Vec3& n,
                  ToiOutput& out) {
    const Vec3 sa = pa.apply(featureCentreSupport(a, pa.orientation.conjugate() * n));
    const Vec3 sb = pb.apply(featureCentreSupport(b, pb.orientation.conjugate() * (-n)));
    const Vec3 a_of_sb = closestPointOnShape(a, pa, sb);
    const Vec3 b_of_sa = closestPointOnShape(b, pb, sa);
    if ((sb - a_of_sb).squaredNorm() <= (b_of_sa - sa).squaredNorm()) {
        out.point_a = a_of_sb;
        out.point_b = sb;
    } else {
        out.point_a = sa;
        out.point_b = b_of_sa;
    }
}

bool validQuery(const ToiQuery& q) {
    return std::isfinite(q.t_max) && std::isfinite(q.target_gap) && std::isfinite(q.tolerance) &&
           std::isfinite(q.relative_tolerance) && q.target_gap >= 0 && q.tolerance >= 0 &&
           q.relative_tolerance >= 0 && std::isfinite(q.deform_speed_a) &&
           std::isfinite(q.deform_speed_b) && q.deform_speed_a >= 0 && q.deform_speed_b >= 0;
}

bool finitePose(const Pose& p) {
    return p.position.allFinite() && p.orientation.coeffs().allFinite();
}

// The rigid motion of timeOfImpact: each shape moved by its sweep.
class RigidMotion final : public AdvancementMotion {
public:
    RigidMotion(const ToiInput& input, Real ra, Real rb)
        : input_(input),
          ra_(ra),
          rb_(rb),
          spin_speed_(spinSpeed(*input.a, input.sweep_a.spin) +
                      spinSpeed(*input.b, input.sweep_b.spin)),
          deform_rate_(deformApproachRate(input.deform_speed_a, input.sweep_a) +
                       deformApproachRate(input.deform_speed_b, input.sweep_b)) {}
    Pose poseA(Real s) const override { return input_.sweep_a.at(s); }
    Pose poseB(Real s) const override { return input_.sweep_b.at(s); }
    Real approachRate(Real, const Vec3& n) const override {
        return sweepApproachRate(input_.sweep_a, input_.sweep_b, n, ra_, rb_, spin_speed_) +
               deform_rate_;
    }

private:
    const ToiInput& input_;
    Real ra_;
    Real rb_;
    Real spin_speed_;
    Real deform_rate_;
};

}  // namespace

bool finiteSweep(const Sweep& s) {
    return s.start.position.allFinite() && s.start.orientation.coeffs().allFinite() &&
           s.translation.allFinite() && s.rotation.allFinite() && s.spin.allFinite();
}

Real spinSpeed(const Shape& shape, const Vec3& spin) {
    const Real w = spin.norm();
    if (!(w > 0)) return 0;
    return w * maxDistanceFromAxis(shape, spin / w);
}

Real shapeBoundingRadius(const Shape& shape) {
    return ConvexCore::fromShape(shape).boundingRadius();
}

Real sweepApproachRate(const Sweep& sweep_a, const Sweep& sweep_b, const Vec3& n, Real ra, Real rb,
                       Real spin_speed) {
    // Translation along n, the speed of the farthest point of each body across n by the world
    // rotation, and the fastest point speed of the body-frame spins (in any direction).
    const Vec3 rel_translation = sweep_a.translation - sweep_b.translation;
    return rel_translation.dot(n) + sweep_a.rotation.cross(n).norm() * ra +
           sweep_b.rotation.cross(n).norm() * rb + spin_speed;
}

Real deformApproachRate(Real deform_speed, const Sweep& sweep) {
    // A point displaced by d <= deform_speed (over the step) from its place on the given shape
    // moves at most deform_speed faster, plus |rotation| d and |spin| d from the body's turning.
    if (!(deform_speed > 0)) return 0;
    return deform_speed * (1 + sweep.rotation.norm() + sweep.spin.norm());
}

Pose Sweep::at(Real t) const {
    Pose p;
    p.position = start.position + t * translation;
    p.orientation = start.orientation;
    const Real angle = rotation.norm();
    if (angle > 0) {
        p.orientation = Quat(Eigen::AngleAxis<Real>(t * angle, rotation / angle)) * p.orientation;
    }
    const Real spin_angle = spin.norm();
    if (spin_angle > 0) {
        p.orientation =
            p.orientation * Quat(Eigen::AngleAxis<Real>(t * spin_angle, spin / spin_angle));
    }
    if (angle > 0 || spin_angle > 0) p.orientation.normalize();
    return p;
}

ToiOutput advanceConservatively(const Shape& a, const Shape& b, const ToiQuery& input,
                                const AdvancementMotion& motion) {
    ToiOutput out;
    out.state = CcdState::Failed;
    if (!validQuery(input)) return out;
    const ConvexCore core_a = ConvexCore::fromShape(a);
    const ConvexCore core_b = ConvexCore::fromShape(b);
    const Real ra = core_a.boundingRadius();
    const Real rb = core_b.boundingRadius();
    const Real scale = std::max(ra, rb);
    const Real tolerance =
        input.tolerance > 0 ? input.tolerance : input.relative_tolerance * std::min(ra, rb);
    const Real t_max = std::clamp(input.t_max, Real(0), Real(1));
    // Deforming shapes (deform_speed_a/_b): a surface point may lie up to D t (D the sum of the
    // two) from where it is on the t = 0 shapes the gap is measured on, so the gap at t is taken
    // D t smaller; the motion's rate includes D (deformApproachRate).
    const Real deform_speed = input.deform_speed_a + input.deform_speed_b;

    Vec3 last_normal = Vec3::Zero();
    Real t = 0;
    for (int iter = 0; iter < input.max_iterations; ++iter) {
        out.iterations = iter + 1;
        const Pose pa = motion.poseA(t);
        const Pose pb = motion.poseB(t);
        if (!finitePose(pa) || !finitePose(pb)) {
            out.state = CcdState::Failed;  // t is still the last safe time
            return out;
        }
        const GjkOutput g = gjkDistance(core_a, core_b, relativePose(pa, pb), scale);
        Vec3 n = Vec3::Zero();
        if (g.state != GjkState::Overlapping) {
            const Vec3& v = g.closest;  // A's frame, points from B to A
            const Real len = v.norm();
            if (len > kEpsilon * scale) n = pa.orientation * (-v / len);
        }
        if (n.squaredNorm() == 0) {
            // The cores touch or overlap (or GJK gave no direction): the full shapes decide.
            const CollideOutput c = collide(a, pa, b, pb);
            out.t = t;
            out.distance = 0;
            out.normal = last_normal;
            if (c.state == ContactState::Penetrating && t == 0) {
                out.state = CcdState::Overlapped;
                return out;
            } else if (c.state == ContactState::Separated) {
                // Rounding left GJK without a direction at a positive gap: fall back to the
                // line of centres, still a valid direction for the lower bound below.
                const Vec3 d = pb.position - pa.position;
                const Real len = d.norm();
                if (!(len > kEpsilon * scale)) return out;  // Failed, t safe
                n = d / len;
            } else {
                // Touching, or penetrating after an advance (only by rounding: every advance
                // was conservative): contact at t.
                out.state = c.state == ContactState::Failed ? CcdState::Failed : CcdState::Hit;
                return out;
            }
        }
        last_normal = n;
        const Real gap = gapAlong(a, pa, b, pb, n) - deform_speed * t;
        out.t = t;
        out.distance = std::max(gap, Real(0));
        out.normal = n;
        setWitnesses(a, pa, b, pb, n, out);
        if (gap <= input.target_gap + tolerance) {
            // Within reach at t. At t = 0 the pair may already interpenetrate (round cores are
            // apart while the shapes overlap): the full shapes decide Overlapped.
            out.state = CcdState::Hit;
            if (t == 0 && gap < 0 && collide(a, pa, b, pb).state == ContactState::Penetrating) {
                out.state = CcdState::Overlapped;
                out.distance = 0;
            }
            return out;
        }
        // Largest rate (per unit t) at which the gap along the fixed n can shrink.
        const Real mu = motion.approachRate(t, n);
        if (std::isnan(mu)) break;  // Failed, t safe
        if (!(mu > 0)) {
            out.state = CcdState::Separated;  // the gap along n never shrinks
            out.t = t_max;
            return out;
        }
        const Real next = t + (gap - input.target_gap) / mu;
        if (!(next < t_max)) {
            out.state = CcdState::Separated;
            out.t = t_max;
            return out;
        }
        t = next;
    }
    out.state = CcdState::Failed;  // cap reached; out.t is the last safe time
    return out;
}

ToiOutput timeOfImpact(const ToiInput& input) {
    if (input.a == nullptr || input.b == nullptr || !finiteSweep(input.sweep_a) ||
        !finiteSweep(input.sweep_b)) {
        return ToiOutput{};
    }
    const RigidMotion motion(input, shapeBoundingRadius(*input.a), shapeBoundingRadius(*input.b));
    return advanceConservatively(*input.a, *input.b, input, motion);
}

}  // namespace collision
