#include "orbit_camera.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace snapthread::viewer {

void OrbitCamera::Fit(const Eigen::Vector3d& box_min, const Eigen::Vector3d& box_max,
                      double aspect, double fill) {
  target_ = 0.5 * (box_min + box_max);
  const double radius = std::max(0.5 * (box_max - box_min).norm(), 1e-6);
  // Half the visible height at distance d is d tan(fov/2); the smaller extent governs.
  const double half_extent = std::tan(0.5 * kFovYRadians) * std::min(1.0, aspect);
  distance_ = radius / (fill * half_extent);
}

void OrbitCamera::Orbit(double dyaw_rad, double dpitch_rad) {
  yaw_rad_ += dyaw_rad;
  pitch_rad_ = std::clamp(pitch_rad_ + dpitch_rad, -1.5, 1.5);
}

void OrbitCamera::SetAngles(double yaw_rad, double pitch_rad) {
  yaw_rad_ = 0.0;
  pitch_rad_ = 0.0;
  Orbit(yaw_rad, pitch_rad);
}

void OrbitCamera::Zoom(double factor) {
  distance_ = std::clamp(distance_ * factor, 1e-4, 1e6);
}

Eigen::Vector3d OrbitCamera::Eye() const {
  const Eigen::Vector3d offset(std::cos(pitch_rad_) * std::sin(yaw_rad_), std::sin(pitch_rad_),
                               std::cos(pitch_rad_) * std::cos(yaw_rad_));
  return target_ + distance_ * offset;
}

Eigen::Matrix4d OrbitCamera::View() const {
  const Eigen::Vector3d eye = Eye();
  const Eigen::Vector3d f = (target_ - eye).normalized();
  const Eigen::Vector3d s = f.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d u = s.cross(f);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

Eigen::Matrix4d OrbitCamera::Projection(double aspect) const {
  const double near = distance_ * 0.01;
  const double far = distance_ * 100.0;
  const double f = 1.0 / std::tan(0.5 * kFovYRadians);
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = f / aspect;
  m(1, 1) = f;
  m(2, 2) = (far + near) / (near - far);
  m(2, 3) = 2.0 * far * near / (near - far);
  m(3, 2) = -1.0;
  return m;
}

Eigen::Vector2d OrbitCamera::ProjectToPixel(const Eigen::Vector3d& p, int width,
                                            int height) const {
  const Eigen::Vector4d clip =
      Projection(double(width) / height) * View() * Eigen::Vector4d(p.x(), p.y(), p.z(), 1.0);
  const double ndc_x = clip.x() / clip.w();
  const double ndc_y = clip.y() / clip.w();
  return {(ndc_x + 1.0) * 0.5 * width, (1.0 - ndc_y) * 0.5 * height};
}

void OrbitCamera::PixelRay(double px, double py, int width, int height,
                           Eigen::Vector3d* origin, Eigen::Vector3d* direction) const {
  const double aspect = double(width) / height;
  const double ndc_x = 2.0 * px / width - 1.0;
  const double ndc_y = 1.0 - 2.0 * py / height;
  const double t = std::tan(0.5 * kFovYRadians);
  const Eigen::Vector3d eye = Eye();
  const Eigen::Vector3d f = (target_ - eye).normalized();
  const Eigen::Vector3d s = f.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d u = s.cross(f);
  *origin = eye;
  *direction = (f + ndc_x * t * aspect * s + ndc_y * t * u).normalized();
}

}  // namespace snapthread::viewer
