// The torque on a grasp that holds its orientation (GraspLayout::grip_rotation, the rod).
// Model::grasp_torque() gives it, null for a model whose grasp holds no orientation (a
// point, or a grip direction whose torque follows from -E_u).
#pragma once

#include <Eigen/Core>

#include "numeric/types.h"

namespace snapthread {

class GraspTorqueCapability {
 public:
  virtual ~GraspTorqueCapability() = default;

  // The torque of the model on the hand about the grasp point, world frame, -dE/dδ for a
  // small world rotation exp([δ]×) of the grasp (the rotation part of -E_u is that torque
  // only while the rotation vector stays on one axis, and loses it at whole turns).
  virtual void GraspTorque(const Vec& x, const Vec& u, Eigen::Vector3d* torque) const = 0;
};

}  // namespace snapthread
