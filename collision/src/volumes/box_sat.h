// collision/src/volumes/box_sat.h -- the boolean separating-axis test of two oriented boxes,
// shared by Obb::overlaps (the broad phases) and the OBB and RSS node volumes of the mesh
// hierarchies. Private to collision.
#pragma once

#include <cmath>

#include "collision/math.h"

namespace collision {

/// Separating-axis test of two boxes (Gottschalk, Lin, Manocha 1996 §4; RTCD 4.4.1) in A's box
/// frame: `a`, `b` half extents, `rot` B's axes in A's box frame, `t` B's centre there. With
/// kSwept, both boxes are additionally swept by spheres of total radius `radius_sum` (RSS): on
/// every axis L the projection grows by radius_sum |L|. Fifteen axes only: for swept volumes this
/// is conservative (the rounded edges are treated as the enclosing box edges).
template <bool kSwept>
inline bool testSat15(const Vec3& a, const Mat3& rot, const Vec3& t, const Vec3& b, Real tol,
                      Real radius_sum) {
    // |R| + eps keeps near-parallel edge pairs (cross product ~ 0) from false separations.
    const Mat3 abs_rot = rot.cwiseAbs().array() + Real(16) * kEpsilon;
    const Real face_slack = tol + (kSwept ? radius_sum : Real(0));
    for (int i = 0; i < 3; ++i) {
        if (std::abs(t[i]) > a[i] + abs_rot.row(i).dot(b) + face_slack) return false;
    }
    for (int j = 0; j < 3; ++j) {
        if (std::abs(t.dot(rot.col(j))) > abs_rot.col(j).dot(a) + b[j] + face_slack) return false;
    }
    for (int i = 0; i < 3; ++i) {
        const int i1 = (i + 1) % 3;
        const int i2 = (i + 2) % 3;
        for (int j = 0; j < 3; ++j) {
            const int j1 = (j + 1) % 3;
            const int j2 = (j + 2) % 3;
            Real slack = tol;
            if constexpr (kSwept) {
                // |A_i x B_j| = |e_i x rot.col(j)| = sqrt(R_i1j^2 + R_i2j^2). Not sqrt(1 - R_ij^2):
                // that rounds to 0 for near-parallel axes and falsely separates (found on a cube
                // whose node axes were 1.7e-7 off the grid).
                slack +=
                    radius_sum * (std::sqrt(rot(i1, j) * rot(i1, j) + rot(i2, j) * rot(i2, j)) +
                                  Real(16) * kEpsilon);
            }
            const Real ra = a[i1] * abs_rot(i2, j) + a[i2] * abs_rot(i1, j);
            const Real rb = b[j1] * abs_rot(i, j2) + b[j2] * abs_rot(i, j1);
            const Real dist = std::abs(t[i2] * rot(i1, j) - t[i1] * rot(i2, j));
            if (dist > ra + rb + slack) return false;
        }
    }
    return true;
}

}  // namespace collision
