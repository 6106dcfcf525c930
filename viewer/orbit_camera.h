// Orbit camera: the view turns about a target point (mouse drag), zooms along the view axis
// (wheel) and fits a bounding box. yaw = pitch = 0 looks down -z with +y up, so planar
// models (z = 0) appear as drawn in the seed: x to the right, y up.
#pragma once

#include <Eigen/Core>

namespace snapthread::viewer {

class OrbitCamera {
 public:
  static constexpr double kFovYRadians = 0.6;  // ~34 degrees vertical field of view

  // Centres the box and sets the distance so that it fills `fill` of the smaller
  // viewport extent (aspect = width / height).
  void Fit(const Eigen::Vector3d& box_min, const Eigen::Vector3d& box_max, double aspect,
           double fill = 0.7);
  void Orbit(double dyaw_rad, double dpitch_rad);
  void SetAngles(double yaw_rad, double pitch_rad);
  void Zoom(double factor);  // distance *= factor

  Eigen::Vector3d Eye() const;
  Eigen::Vector3d Target() const { return target_; }
  Eigen::Matrix4d View() const;
  Eigen::Matrix4d Projection(double aspect) const;
  // Pixel (x right, y DOWN, origin top-left) of a world point in a width x height viewport.
  Eigen::Vector2d ProjectToPixel(const Eigen::Vector3d& p, int width, int height) const;
  // Ray through a pixel (same pixel convention): origin and unit direction.
  void PixelRay(double px, double py, int width, int height, Eigen::Vector3d* origin,
                Eigen::Vector3d* direction) const;
  double Distance() const { return distance_; }

 private:
  Eigen::Vector3d target_ = Eigen::Vector3d::Zero();
  double distance_ = 5.0;
  double yaw_rad_ = 0.0;
  double pitch_rad_ = 0.0;
};

}  // namespace snapthread::viewer
