#include "pose_mapping.h"

#include <cmath>

namespace snapthread::server {

Eigen::Vector3d GripDirection(const Eigen::Vector4d& quaternion_wxyz) {
  const double norm = quaternion_wxyz.norm();
  if (!(norm > 0.0) || !std::isfinite(norm)) return Eigen::Vector3d::UnitX();
  const Eigen::Vector4d q = quaternion_wxyz / norm;
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  // First column of the rotation matrix of a unit quaternion.
  return Eigen::Vector3d(1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z),
                         2.0 * (x * z - w * y));
}

Vec PoseToControls(const DeviceMapping& mapping, const Model& model,
                   const Eigen::Vector3d& position_m, const Eigen::Vector4d& quaternion_wxyz) {
  const int dim = model.SpatialDimension();
  Vec u = Vec::Zero(model.NumControls());
  for (int i = 0; i < dim && i < u.size(); ++i) {
    u[i] = mapping.model_origin[i] + mapping.model_units_per_metre * position_m[i];
  }
  // thread3d with a grip direction: u = (X, Y, Z, dx, dy, dz).
  if (u.size() >= dim + 3) u.segment<3>(dim) = GripDirection(quaternion_wxyz);
  return u;
}

Eigen::Vector3d ControlsToPosition(const DeviceMapping& mapping, const Model& model, const Vec& u) {
  const int dim = model.SpatialDimension();
  Eigen::Vector3d p(0.0, 0.0, PlanarZ0(mapping));
  for (int i = 0; i < dim && i < 3 && i < u.size(); ++i) {
    p[i] = (u[i] - mapping.model_origin[i]) / mapping.model_units_per_metre;
  }
  return p;
}

double PlanarZ0(const DeviceMapping& mapping) {
  return -mapping.model_origin[2] / mapping.model_units_per_metre;
}

}  // namespace snapthread::server
