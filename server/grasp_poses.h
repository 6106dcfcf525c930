// Several grasps on one session: each device pose moves only the controls of
// the grasp it names (device_state_t.grasp); the other grasps keep the controls of the
// last update, so one solve answers every hand whose pose arrived.
//
// A grasp that holds its orientation (GraspLayout::grip_rotation, the rod) has a
// rotation vector φ among its controls, and a quaternion names the rotation only up to
// the 2π turns of φ. The model continues the grasp's material angle whatever φ names
// the rotation, but the tracker's predictor needs controls that move continuously, and
// the wrench's chart change needs J_l(φ) well conditioned (singular at |φ| = 2π). So φ
// is the representative of the pose's rotation nearest the grasp's current φ, until
// |φ| passes kRelabelAngle; then the pose takes its principal φ (|φ| <= π) and the
// tracker's current controls are renamed to the representative nearest it first
// (EquilibriumTracker::RelabelControls). The hysteresis (π .. 1.25π) keeps a hand that
// hovers at half a turn from renaming at every pose.
#pragma once

#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "scene/scene.h"
#include "server_inbox.h"

namespace snapthread::server {

constexpr double kRelabelAngle = 1.25 * std::numbers::pi;

// For each pose, the index in scene.grasps of the grasp it names (-1: no such grasp; ""
// is the first), with that grasp's controls written into *u (size: every grasp's
// controls; on entry the tracker's controls: the slices of grasps without a pose are
// left as they are). renamed (optional): the tracker's controls under the names the
// new ones continue: equal to *u on entry unless a rotation vector was renamed. Without
// it φ only continues (never renamed).
std::vector<int> ApplyGraspPoses(const Scene& scene, const Eigen::Vector3d& rest_direction,
                                 const std::vector<ReceivedPose>& poses, Vec* u,
                                 Vec* renamed = nullptr);

}  // namespace snapthread::server
