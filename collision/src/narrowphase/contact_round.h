// collision/src/narrowphase/contact_round.h -- contact() in closed form for the round pairs
// (sphere-sphere, sphere-capsule, capsule-capsule; RTCD 5.1.9), in the canonically-first shape's
// frame, from the same core computation as collide()'s closed forms (collide_pairs.h), whose
// signed distance both classify. Inline: contact() calls them directly, so a round pair's answer
// stays in registers until the world transform (contact.cpp); private to collision.
#pragma once

#include "narrowphase/contact_pairs.h"

namespace collision::contact_pairs {

// Both shapes reduce to points/segments inflated by radii: the closest core points on_a and on_b
// (collide()'s own, collide_pairs.h), direction from A to B. Witness points are the cores' points
// pushed out by the radii.
inline void roundContact(Real ra, Real rb, const collide_pairs::RoundCores& cores,
                         const Vec3& fallback_normal, const Ctx& ctx, Local& out) {
    const Real d = cores.distance;
    out.normal = d > kDirectionRelative * ctx.scale ? Vec3((cores.on_b - cores.on_a) / d)
                                                     : fallback_normal;
    out.signed_distance = d - ra - rb;
    out.point_a = cores.on_a + ra * out.normal;
    out.point_b = cores.on_b - rb * out.normal;
}

inline CollideOutput sphereSphere(const Shape& a, const Shape& b, const RelativePose& rel,
                                  const Ctx& ctx, Local& out) {
    // Coincident centres: A's local +x.
    roundContact(a.radius, b.radius, collide_pairs::sphereSphereCores(rel), Vec3::UnitX(), ctx,
                 out);
    out.feature_a = {FeatureType::Face, 0};
    out.feature_b = {FeatureType::Face, 0};
    return classifySignedDistance(out.signed_distance, ctx.tolerance);
}

inline CollideOutput sphereCapsule(const Shape& a, const Shape& b, const RelativePose& rel,
                                   const Ctx& ctx, Local& out) {
    // Centre on the axis: the sphere leaves along B's local -x (so the normal is B's +x).
    roundContact(a.radius, b.radius, collide_pairs::sphereCapsuleCores(b, rel),
                 rel.rotation.col(0), ctx, out);
    out.feature_a = {FeatureType::Face, 0};
    const Real y = toB(rel, Vec3::Zero()).y();
    if (y < -b.half_height) {
        out.feature_b = {FeatureType::Vertex, 0};
    } else if (y > b.half_height) {
        out.feature_b = {FeatureType::Vertex, 1};
    } else {
        out.feature_b = {FeatureType::Edge, 0};
    }
    return classifySignedDistance(out.signed_distance, ctx.tolerance);
}

inline CollideOutput capsuleCapsule(const Shape& a, const Shape& b, const RelativePose& rel,
                                    const Ctx& ctx, Local& out) {
    const collide_pairs::RoundCores cores = collide_pairs::capsuleCapsuleCores(a, b, rel, ctx);
    const Vec3 axis_b = rel.rotation.col(1);
    // Crossing axes: the common perpendicular (towards B's centre); parallel axes: the component
    // of B's centre off A's axis, else A's local +x.
    Vec3 fallback = Vec3::UnitY().cross(axis_b);
    if (fallback.norm() > kParallelSin) {
        fallback.normalize();
    } else {
        fallback = Vec3(rel.position.x(), 0, rel.position.z());
        const Real len = fallback.norm();
        fallback = len > kDirectionRelative * ctx.scale ? Vec3(fallback / len) : Vec3::UnitX();
    }
    if (fallback.dot(rel.position) < 0) fallback = -fallback;
    roundContact(a.radius, b.radius, cores, fallback, ctx, out);
    const Real tol = kFeatureRelative * ctx.scale;
    out.feature_a = capsuleFeature(a.half_height, cores.on_a, tol);
    out.feature_b = capsuleFeature(b.half_height, toB(rel, cores.on_b), tol);
    return classifySignedDistance(out.signed_distance, ctx.tolerance);
}

}  // namespace collision::contact_pairs
