#include "messages/pose_mapping.h"

#include <cmath>

#include <Eigen/Geometry>

namespace snapthread::server {

Eigen::Vector3d GripDirection(const Eigen::Vector4d& quaternion_wxyz,
                              const Eigen::Vector3d& rest) {
  const double rest_norm = rest.norm();
  const Eigen::Vector3d r = (rest_norm > 0.0 && std::isfinite(rest_norm))
                                ? Eigen::Vector3d(rest / rest_norm)
                                : Eigen::Vector3d::UnitX();
  const double norm = quaternion_wxyz.norm();
  if (!(norm > 0.0) || !std::isfinite(norm)) return r;
  const Eigen::Quaterniond q(quaternion_wxyz[0] / norm, quaternion_wxyz[1] / norm,
                             quaternion_wxyz[2] / norm, quaternion_wxyz[3] / norm);
  return q * r;
}

Eigen::Vector3d RestGripDirection(const Scene& scene, const Model& model) {
  const int dim = model.SpatialDimension();
  if (model.NumControls() >= dim + 3 && scene.grasp_start.size() >= dim + 3) {
    const Eigen::Vector3d d = scene.grasp_start.segment<3>(dim);
    if (d.norm() > 0.0 && d.allFinite()) return d.normalized();
  }
  return Eigen::Vector3d::UnitX();
}

Vec PoseToControls(const DeviceMapping& mapping, const Model& model,
                   const Eigen::Vector3d& position_m, const Eigen::Vector4d& quaternion_wxyz,
                   const Eigen::Vector3d& rest_direction) {
  const int dim = model.SpatialDimension();
  Vec u = Vec::Zero(model.NumControls());
  for (int i = 0; i < dim && i < u.size(); ++i) {
    u[i] = mapping.model_origin[i] + mapping.model_units_per_metre * position_m[i];
  }
  // thread3d with a grip direction: u = (X, Y, Z, dx, dy, dz).
  if (u.size() >= dim + 3) u.segment<3>(dim) = GripDirection(quaternion_wxyz, rest_direction);
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
