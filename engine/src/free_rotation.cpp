// engine/src/free_rotation.cpp -- see free_rotation.h.
// In principal coordinates the orientation is P = R Q (principal -> world) and the body's
// angular momentum L_p = P^T L. The flow of c L_i^2 spins the body about its own principal axis
// e_i at the rate 2 c L_i: P <- P Rot(e_i, 2 c L_i tau), which leaves L_i unchanged, so each
// sub-flow is exact and the composition is symplectic.
#include "engine/free_rotation.h"

#include <Eigen/Eigenvalues>

namespace engine {

PrincipalFrame principalFrame(const Mat3& inertia_body) {
    const Mat3 symmetric = Real(0.5) * (inertia_body + inertia_body.transpose());
    Eigen::SelfAdjointEigenSolver<Mat3> solver;
    solver.compute(symmetric);  // iterative: computeDirect loses ~1e-8 on repeated moments
    Mat3 q = solver.eigenvectors();
    if (q.determinant() < 0) q.col(2) = -q.col(2);
    PrincipalFrame frame;
    frame.axes = Quat(q).normalized();
    frame.moments = solver.eigenvalues();
    return frame;
}

Quat advanceFreeRotation(const Quat& orientation, const Vec3& angular_momentum,
                         const PrincipalFrame& frame, Real dt) {
    // Splitting about the middle moment I2 (Fasso 2003): H = |L|^2 / (2 I2) + c1 L1^2 + c3 L3^2,
    // c_i = 1 / (2 I_i) - 1 / (2 I2). The first term spins the body about the fixed world L at
    // |L| / I2 (a left rotation; it commutes with the rest since L_p is unchanged by it), the
    // others about body axes 1 and 3 at 2 c_i L_i (right rotations), composed as Strang
    // c1 (dt/2), c3 (dt), c1 (dt/2). Spherical and axisymmetric bodies (c1 or c3 = 0) are then
    // integrated exactly; asymmetric ones at second order with a bounded energy error.
    Quat p = orientation * frame.axes;  // principal -> world
    const Real l_norm = angular_momentum.norm();
    if (!(l_norm > 0)) return orientation;
    const Real i2 = frame.moments[1];
    auto spinBody = [&](int axis, Real tau) {
        const Real c = Real(0.5) / frame.moments[axis] - Real(0.5) / i2;
        if (c == 0) return;
        const Vec3 l_principal = p.conjugate() * angular_momentum;
        const Real angle = 2 * c * l_principal[axis] * tau;
        if (angle == 0) return;
        p = p * Quat(Eigen::AngleAxis<Real>(angle, Vec3::Unit(axis)));
    };
    p = Quat(Eigen::AngleAxis<Real>(l_norm / i2 * dt, angular_momentum / l_norm)) * p;
    spinBody(0, dt / 2);
    spinBody(2, dt);
    spinBody(0, dt / 2);
    return (p * frame.axes.conjugate()).normalized();
}

}  // namespace engine
