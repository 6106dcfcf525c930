// Several grasps on one session (issue 15): each device pose moves only the controls of
// the grasp it names (device_state_t.grasp); the other grasps keep the controls of the
// last update, so one solve answers every hand whose pose arrived.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "scene/scene.h"
#include "server_inbox.h"

namespace snapthread::server {

// For each pose, the index in scene.grasps of the grasp it names (-1: no such grasp; ""
// is the first), with that grasp's controls written into *u (size: every grasp's
// controls; the slices of grasps without a pose are left as they are).
std::vector<int> ApplyGraspPoses(const Scene& scene, const Eigen::Vector3d& rest_direction,
                                 const std::vector<PoseSample>& poses, Vec* u);

}  // namespace snapthread::server
