// engine/src/body.cpp -- derived quantities of a rigid body.
#include "engine/body.h"

#include <utility>

namespace engine {

Mat3 Body::invInertiaWorld() const {
    const Mat3 r = orientation.toRotationMatrix();
    return r * inv_inertia_body * r.transpose();
}

Vec3 Body::angularVelocity() const { return invInertiaWorld() * angular_momentum; }

Real Body::kineticEnergy() const {
    const Vec3 v = velocity();
    return Real(0.5) * mass * v.squaredNorm() + Real(0.5) * angularVelocity().dot(angular_momentum);
}

Body makeBody(std::string name, collision::Shape shape, const MassProperties& mass) {
    Body b;
    b.name = std::move(name);
    b.local_bounds = collision::fitLocalBounds(shape);
    b.shape = std::move(shape);
    b.mass = mass.mass;
    b.inv_mass = Real(1) / mass.mass;
    b.inertia_body = mass.inertia;
    b.inv_inertia_body = mass.inertia.inverse();
    return b;
}

}  // namespace engine
