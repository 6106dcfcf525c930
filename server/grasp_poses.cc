#include "grasp_poses.h"

#include "messages/pose_mapping.h"
#include "numeric/so3.h"

namespace snapthread::server {

std::vector<int> ApplyGraspPoses(const Scene& scene, const Eigen::Vector3d& rest_direction,
                                 const std::vector<ReceivedPose>& poses, Vec* u, Vec* renamed) {
  std::vector<int> grasp_of;
  grasp_of.reserve(poses.size());
  const int m = scene.grasp_layout.NumControls();
  const int dim = scene.grasp_layout.spatial_dimension;
  const bool rotation = scene.grasp_layout.grip_rotation && m >= dim + 3;
  if (renamed != nullptr) *renamed = *u;
  for (const ReceivedPose& pose : poses) {
    int g = FindGrasp(scene, pose.state.grasp);
    const int offset = scene.grasps.empty() ? 0 : scene.grasps[g < 0 ? 0 : g].offset;
    if (g >= 0 && offset + m > u->size()) g = -1;
    grasp_of.push_back(g);
    if (g < 0) continue;
    const Eigen::Vector3d position(pose.state.position[0], pose.state.position[1], pose.state.position[2]);
    const Eigen::Vector4d quaternion(pose.state.orientation[0], pose.state.orientation[1],
                                     pose.state.orientation[2], pose.state.orientation[3]);
    Vec controls =
        messages::PoseToControls(GraspDeviceMapping(scene, g), scene.grasp_layout, position, quaternion, rest_direction);
    if (rotation) {
      const int at = offset + dim;
      const Eigen::Vector3d principal = controls.segment<3>(dim);
      const Eigen::Vector3d current = u->segment<3>(at);
      Eigen::Vector3d phi = so3::NearestRepresentative(principal, current);
      if (renamed != nullptr && phi.norm() > kRelabelAngle) {
        phi = principal;
        renamed->segment<3>(at) = so3::NearestRepresentative(renamed->segment<3>(at), phi);
      }
      controls.segment<3>(dim) = phi;
    }
    u->segment(offset, m) = controls;
  }
  return grasp_of;
}

}  // namespace snapthread::server
