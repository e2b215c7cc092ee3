// render/camera_moves.h -- a demo's camera moves on engine::CameraSettings: orbit about the point
// looked at, zoom, pan in the view plane, follow a point. Pure functions of the camera: the same
// moves in the same order give the same camera to the last bit.
#pragma once

#include "engine/scene.h"

namespace render {

/// Turns the eye about the point looked at: `yaw_deg` about `up` (positive: the view turns
/// right), then `pitch_deg` about the view's right axis (positive: the eye rises). The angle
/// between the view and `up` is kept within [1, 179] degrees, so the view never flips.
engine::CameraSettings orbitCamera(const engine::CameraSettings& camera, engine::Real yaw_deg,
                                   engine::Real pitch_deg);

/// The eye moved along the view so that its distance to the point looked at is divided by
/// `factor` (> 0).
engine::CameraSettings zoomCamera(const engine::CameraSettings& camera, engine::Real factor);

/// Eye and point looked at moved together by `right` metres along the view's right axis and
/// `up` metres along its up axis.
engine::CameraSettings panCamera(const engine::CameraSettings& camera, engine::Real right,
                                 engine::Real up);

/// The camera moved (eye and point looked at together) so that it looks at `target`.
engine::CameraSettings lookAtPoint(const engine::CameraSettings& camera,
                                   const engine::Vec3& target);

}  // namespace render
