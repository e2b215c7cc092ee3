// engine/body.h -- a rigid body: its shape, mass properties and state.
// State is (position of the centre of mass, unit orientation, linear momentum P, angular momentum
// L, world frame); velocities are derived: v = P/m, w = R I_body^-1 R^T L.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "collision/geometry/shape.h"
#include "collision/math.h"
#include "collision/volumes/bounding_volumes.h"
#include "engine/deformation.h"

namespace engine {

using collision::Mat3;
using collision::Pose;
using collision::Quat;
using collision::Real;
using collision::Vec3;

using BodyId = std::int32_t;

/// Mass properties about the centre of mass, in the body frame.
struct MassProperties {
    Real mass = 0;                    ///< kg, > 0
    Vec3 center_of_mass = Vec3::Zero();  ///< in the shape's input frame, before re-centring
    Mat3 inertia = Mat3::Identity();  ///< kg m^2 about the centre of mass, symmetric positive
};

struct Body {
    std::string name;
    collision::Shape shape;             ///< local frame origin = centre of mass
    collision::LocalBounds local_bounds;
    Real mass = 1;
    Real inv_mass = 1;
    Mat3 inertia_body = Mat3::Identity();
    Mat3 inv_inertia_body = Mat3::Identity();
    /// Principal frame of the inertia in the body frame (a proper rotation; its columns are the
    /// principal axes) and the principal moments, ascending (kg m^2). Set by makeBody.
    Quat principal_frame = Quat::Identity();
    Vec3 principal_moments = Vec3::Ones();
    Real restitution = Real(0.5);  ///< in [0, 1]; a pair uses the larger of its two
    Real friction = Real(0.5);     ///< Coulomb coefficient >= 0; a pair uses sqrt(mu_a mu_b)
    /// Infinite mass: inv_mass = 0, inverse inertia 0, zero momenta; never moves (setStatic).
    bool is_static = false;
    /// A chain's link (engine/chain.h): its pose is prescribed by the chain's joint
    /// trajectories and set by the World every step; also is_static (infinite mass, zero
    /// momenta, never integrated).
    bool kinematic = false;
    /// Mesh bodies only: every step the world lists the body's own intersecting triangle pairs
    /// (World::selfPairs). Scene key `self_collision`.
    bool self_collision = false;
    /// Mesh bodies only: prescribed shape change; the world moves the vertices and refits the
    /// body's own hierarchy every step (World::step). Scene key `deform`.
    std::optional<Deformation> deform;

    Vec3 position = Vec3::Zero();       ///< m, centre of mass, world
    Quat orientation = Quat::Identity();
    Vec3 linear_momentum = Vec3::Zero();   ///< kg m/s
    Vec3 angular_momentum = Vec3::Zero();  ///< kg m^2/s, world frame, about the centre of mass

    Pose pose() const { return Pose{position, orientation}; }
    Vec3 velocity() const { return linear_momentum * inv_mass; }
    /// World angular velocity (rad/s).
    Vec3 angularVelocity() const;
    /// World inverse inertia R I^-1 R^T.
    Mat3 invInertiaWorld() const;
    /// 1/2 m v^2 + 1/2 w.L (J).
    Real kineticEnergy() const;
};

/// Makes `body` static (immovable, infinite mass and inertia): zero inverses and momenta.
/// `mass` and `inertia_body` keep the values of the shape, for reference.
void setStatic(Body& body);

/// Builds a body from a shape and its mass properties; fits the local bounding volumes.
Body makeBody(std::string name, collision::Shape shape, const MassProperties& mass);

}  // namespace engine
