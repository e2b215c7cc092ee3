// engine/src/body.cpp -- derived quantities of a rigid body.
#include "engine/body.h"

#include <utility>

#include <Eigen/Eigenvalues>

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

void setStatic(Body& body) {
    body.is_static = true;
    body.inv_mass = 0;
    body.inv_inertia_body = Mat3::Zero();
    body.linear_momentum = Vec3::Zero();
    body.angular_momentum = Vec3::Zero();
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
    // Principal axes for the splitting integrator (world.cpp): I = V diag(moments) V^T.
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(mass.inertia);
    Mat3 v = eig.eigenvectors();
    if (v.determinant() < 0) v.col(2) = -v.col(2);  // a proper rotation
    b.principal_frame = Quat(v).normalized();
    b.principal_moments = eig.eigenvalues();
    return b;
}

}  // namespace engine
