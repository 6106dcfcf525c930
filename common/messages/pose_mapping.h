// Device pose (metres, device frame) <-> model controls u: the one mapping used by the
// device client, the server, the viewer's grasp mode and the report. It needs only the
// scene's DeviceMapping and GraspLayout (Scene::grasp_layout), never a Model:
//   u_model = model_origin + model_units_per_metre * position_m.
//  * planar layouts (spatial_dimension 2): u = (X, Y) from the pose's x and y; the
//    device's z is held near the model plane by a stiff virtual plane (the server's
//    force model, PlanarZ0).
//  * spatial layouts (3): u = (X, Y, Z); with a constrained grip direction also
//    (dx, dy, dz), the orientation quaternion applied to the device's grip axis
//    (lcmtypes/device_state_t.lcm: R * (1, 0, 0)), expressed in the scene: the device's
//    rest orientation holds the grip the way the scene starts (grasp.direction),
//    d = R(q) d_start. This is R(q) (1, 0, 0) exactly when the scene starts along +x, and
//    it lets devices that sense no orientation (they report the identity; so do sim-path
//    and virtual-hand outside rod scenes) hold the scene's grip instead of turning it to +x, as
//    model_origin does for positions.
//  * a grasp that holds its full orientation (GraspLayout::grip_rotation, the rod):
//    u = (X, Y, Z, φ) with exp([φ]×) = R(q): the device at rest holds the scene's start
//    orientation, and the grasp turns by the device's rotation from rest (both in the
//    scene's frame, which the position mapping does not rotate). |φ| <= π here; the
//    server keeps φ continuous across half turns (server/grasp_poses.h).
#pragma once

#include <Eigen/Core>

#include "numeric/types.h"
#include "scene/scene.h"

namespace snapthread::messages {

// A point: device metres -> model units, and back (all three coordinates).
Eigen::Vector3d DeviceToModelPoint(const DeviceMapping& mapping, const Eigen::Vector3d& position_m);
Eigen::Vector3d ModelPointToDevice(const DeviceMapping& mapping, const Eigen::Vector3d& model_point);

// R(q) rest for q = (w, x, y, z); q is normalised first (a zero quaternion counts as the
// identity), rest too (a zero rest counts as (1, 0, 0)).
Eigen::Vector3d GripDirection(const Eigen::Vector4d& quaternion_wxyz,
                              const Eigen::Vector3d& rest = Eigen::Vector3d::UnitX());

// The grip direction a device at rest (identity orientation) holds in this scene: the
// scene's start direction (grasp_start after the position) for layouts with a grip,
// else (1, 0, 0).
Eigen::Vector3d RestGripDirection(const Scene& scene);

// Controls u (size layout.NumControls()) for a device pose; rest_direction as given by
// RestGripDirection (used only by layouts with a grip direction).
Vec PoseToControls(const DeviceMapping& mapping, const GraspLayout& layout,
                   const Eigen::Vector3d& position_m, const Eigen::Vector4d& quaternion_wxyz,
                   const Eigen::Vector3d& rest_direction = Eigen::Vector3d::UnitX());

// The device position (metres) that maps to the positional controls of u (inverse of
// PoseToControls; z = the model plane for planar layouts). Used by scripted paths, tests
// and the reference computations.
Eigen::Vector3d ControlsToPosition(const DeviceMapping& mapping, const GraspLayout& layout,
                                   const Vec& u);

// The device orientation (w, x, y, z) that maps to the rotation controls of u (inverse
// of PoseToControls for grip_rotation layouts: exp([φ]×) as a quaternion; identity for
// other layouts). Used by the scripted paths, so a rod scene's path rolls the grasp.
Eigen::Vector4d ControlsToOrientation(const GraspLayout& layout, const Vec& u);

// Device z (metres) of the model plane z_model = 0 for planar layouts:
// z_model = origin_z + scale * z  =>  z0 = -origin_z / scale.
double PlanarZ0(const DeviceMapping& mapping);

}  // namespace snapthread::messages
