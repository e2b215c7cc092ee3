// tests/engine/test_mass.h -- mass properties of solid boxes and spheres written out from their
// textbook formulas, so the dynamics tests do not take them from the engine they test.
#pragma once

#include "engine/body.h"

namespace engine {

/// A solid box of half extents h: I_xx = m/3 (h_y^2 + h_z^2), and so on.
inline MassProperties boxMass(const Vec3& h, Real mass) {
    MassProperties m;
    m.mass = mass;
    m.inertia = Vec3(h.y() * h.y() + h.z() * h.z(), h.x() * h.x() + h.z() * h.z(),
                     h.x() * h.x() + h.y() * h.y())
                    .asDiagonal();
    m.inertia *= mass / 3;
    return m;
}

/// A solid sphere of radius r: I = 2/5 m r^2 about every axis.
inline MassProperties sphereMass(Real r, Real mass) {
    MassProperties m;
    m.mass = mass;
    m.inertia = Mat3::Identity() * (Real(0.4) * mass * r * r);
    return m;
}

}  // namespace engine
