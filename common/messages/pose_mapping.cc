#include "messages/pose_mapping.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "numeric/so3.h"

namespace snapthread::messages {
namespace {

Eigen::Vector3d Origin(const DeviceMapping& m) {
  return Eigen::Vector3d(m.model_origin[0], m.model_origin[1], m.model_origin[2]);
}

int PositionalControls(const GraspLayout& layout) {
  return std::clamp(layout.spatial_dimension, 0, 3);
}

}  // namespace

Eigen::Vector3d DeviceToModelPoint(const DeviceMapping& mapping, const Eigen::Vector3d& position_m) {
  return Origin(mapping) + mapping.model_units_per_metre * position_m;
}

Eigen::Vector3d ModelPointToDevice(const DeviceMapping& mapping, const Eigen::Vector3d& model_point) {
  return (model_point - Origin(mapping)) / mapping.model_units_per_metre;
}

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

Eigen::Vector3d RestGripDirection(const Scene& scene) {
  const GraspLayout& layout = scene.grasp_layout;
  const int dim = layout.spatial_dimension;
  if (layout.grip_direction && scene.grasp_start.size() >= dim + 3) {
    const Eigen::Vector3d d = scene.grasp_start.segment<3>(dim);
    if (d.norm() > 0.0 && d.allFinite()) return d.normalized();
  }
  return Eigen::Vector3d::UnitX();
}

Vec PoseToControls(const DeviceMapping& mapping, const GraspLayout& layout,
                   const Eigen::Vector3d& position_m, const Eigen::Vector4d& quaternion_wxyz,
                   const Eigen::Vector3d& rest_direction) {
  const int dim = PositionalControls(layout);
  Vec u = Vec::Zero(layout.NumControls());
  const Eigen::Vector3d model_point = DeviceToModelPoint(mapping, position_m);
  for (int i = 0; i < dim && i < u.size(); ++i) u[i] = model_point[i];
  // A grip direction: u = (X, Y, Z, dx, dy, dz).
  if (layout.grip_direction && u.size() >= dim + 3) {
    u.segment<3>(dim) = GripDirection(quaternion_wxyz, rest_direction);
  }
  // A full orientation: u = (X, Y, Z, φ), exp([φ]×) = R(q) (the grasp turns from the
  // scene's start by the device's rotation from rest), |φ| <= π.
  if (layout.grip_rotation && u.size() >= dim + 3) {
    u.segment<3>(dim) = so3::LogQuaternion(quaternion_wxyz[0], quaternion_wxyz[1],
                                           quaternion_wxyz[2], quaternion_wxyz[3]);
  }
  return u;
}

Eigen::Vector3d ControlsToPosition(const DeviceMapping& mapping, const GraspLayout& layout,
                                   const Vec& u) {
  const int dim = PositionalControls(layout);
  Eigen::Vector3d model_point = Origin(mapping);
  model_point[2] = 0.0;  // planar layouts: the model plane z_model = 0 (PlanarZ0)
  for (int i = 0; i < dim && i < u.size(); ++i) model_point[i] = u[i];
  return ModelPointToDevice(mapping, model_point);
}

Eigen::Vector4d ControlsToOrientation(const GraspLayout& layout, const Vec& u) {
  const int dim = PositionalControls(layout);
  if (!layout.grip_rotation || u.size() < dim + 3) return Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);
  const Eigen::Vector3d phi = u.segment<3>(dim);
  if (!phi.allFinite()) return Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);
  return so3::ExpQuaternion(phi);
}

double PlanarZ0(const DeviceMapping& mapping) {
  return -mapping.model_origin[2] / mapping.model_units_per_metre;
}

}  // namespace snapthread::messages
