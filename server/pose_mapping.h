// Device pose (metres, device frame) <-> model controls u, through the scene's
// DeviceMapping: u_model = model_origin + model_units_per_metre * position_m.
//  * planar models (zeeman, cusp, curve2d): u = (X, Y) from the pose's x and y; the
//    device's z is held near the model plane by a stiff virtual plane (force_model.h).
//  * thread3d: u = (X, Y, Z); with a constrained grip direction also (dx, dy, dz), the
//    orientation quaternion applied to (1, 0, 0) (lcmtypes/device_state_t.lcm).
#pragma once

#include <Eigen/Core>

#include "snapthread/model.h"
#include "snapthread/scene.h"
#include "snapthread/types.h"

namespace snapthread::server {

// R(q) (1, 0, 0) for q = (w, x, y, z); q is normalised first (a zero quaternion gives
// (1, 0, 0): the identity grip).
Eigen::Vector3d GripDirection(const Eigen::Vector4d& quaternion_wxyz);

// Controls u (size model.NumControls()) for a device pose.
Vec PoseToControls(const DeviceMapping& mapping, const Model& model,
                   const Eigen::Vector3d& position_m, const Eigen::Vector4d& quaternion_wxyz);

// The device position (metres) that maps to the positional controls of u (inverse of
// PoseToControls; z = the model plane for planar models). Used by scripted paths, tests
// and the reference computations.
Eigen::Vector3d ControlsToPosition(const DeviceMapping& mapping, const Model& model, const Vec& u);

// Device z (metres) of the model plane z_model = 0 for planar models:
// z_model = origin_z + scale * z  =>  z0 = -origin_z / scale.
double PlanarZ0(const DeviceMapping& mapping);

}  // namespace snapthread::server
