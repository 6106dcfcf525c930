#include "grasp_poses.h"

#include "messages/pose_mapping.h"

namespace snapthread::server {

std::vector<int> ApplyGraspPoses(const Scene& scene, const Eigen::Vector3d& rest_direction,
                                 const std::vector<PoseSample>& poses, Vec* u) {
  std::vector<int> grasp_of;
  grasp_of.reserve(poses.size());
  const int m = scene.grasp_layout.NumControls();
  for (const PoseSample& pose : poses) {
    int g = FindGrasp(scene, pose.state.grasp);
    const int offset = scene.grasps.empty() ? 0 : scene.grasps[g < 0 ? 0 : g].offset;
    if (g >= 0 && offset + m > u->size()) g = -1;
    grasp_of.push_back(g);
    if (g < 0) continue;
    const Eigen::Vector3d position(pose.state.position[0], pose.state.position[1], pose.state.position[2]);
    const Eigen::Vector4d quaternion(pose.state.orientation[0], pose.state.orientation[1],
                                     pose.state.orientation[2], pose.state.orientation[3]);
    u->segment(offset, m) =
        messages::PoseToControls(GraspDeviceMapping(scene, g), scene.grasp_layout, position, quaternion, rest_direction);
  }
  return grasp_of;
}

}  // namespace snapthread::server
