#include "topology/closure.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

namespace snapthread::topology {
namespace {

// Unit direction in which an end leaves: away from the centroid, or along its tangent.
Eigen::Vector3d EndDirection(const Eigen::Vector3d& end, const Eigen::Vector3d& inner,
                             const Eigen::Vector3d& centroid, double radius) {
  Eigen::Vector3d d = end - centroid;
  if (d.norm() > 1e-9 * radius) return d.normalized();
  d = end - inner;
  if (d.norm() > 0.0) return d.normalized();
  return Eigen::Vector3d::UnitX();
}

// Points of the great-circle arc from unit a to unit b (both excluded), steps of <= 15 deg.
void AppendArc(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
               double r, std::vector<Eigen::Vector3d>& out) {
  const double angle = std::acos(std::clamp(a.dot(b), -1.0, 1.0));
  const int steps = std::max(1, static_cast<int>(std::ceil(angle / (M_PI / 12.0))));
  const double s = std::sin(angle);
  for (int k = 1; k < steps; ++k) {
    const double f = static_cast<double>(k) / steps;
    const Eigen::Vector3d d = (std::sin((1.0 - f) * angle) * a + std::sin(f * angle) * b) / s;
    out.push_back(c + r * d.normalized());
  }
}

}  // namespace

std::vector<Eigen::Vector3d> CloseFarAway(std::span<const Eigen::Vector3d> nodes) {
  std::vector<Eigen::Vector3d> out(nodes.begin(), nodes.end());
  const std::size_t n = nodes.size();
  if (n < 2) return out;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : nodes) centroid += p;
  centroid /= static_cast<double>(n);
  double radius = 0.0;
  for (const auto& p : nodes) radius = std::max(radius, (p - centroid).norm());
  if (radius <= 0.0) return out;
  const double r = 3.0 * radius;
  Eigen::Vector3d d_end = EndDirection(nodes[n - 1], nodes[n - 2], centroid, radius);
  Eigen::Vector3d d_start = EndDirection(nodes[0], nodes[1], centroid, radius);
  // A planar curve (curve2d, or a thread lying flat): the radial way out of an inner end
  // would cut the curve in its own plane, where no crossing has an over and an under. Both
  // ends leave at 45 degrees to one side of the plane instead, over everything.
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : nodes) scatter += (p - centroid) * (p - centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  if (eig.eigenvalues()[0] <= 1e-20 * radius * radius * static_cast<double>(n)) {
    const Eigen::Vector3d normal = eig.eigenvectors().col(0);
    auto tilt = [&](const Eigen::Vector3d& d) -> Eigen::Vector3d {
      const Eigen::Vector3d in_plane = d - d.dot(normal) * normal;
      if (in_plane.norm() < 1e-9) return normal;
      return (in_plane.normalized() + normal).normalized();
    };
    d_end = tilt(d_end);
    d_start = tilt(d_start);
  }
  out.push_back(centroid + r * d_end);
  if (d_end.dot(d_start) < -0.999) {
    // Nearly antipodal: go through a point a quarter turn away from both.
    Eigen::Vector3d m = d_end.unitOrthogonal();
    AppendArc(d_end, m, centroid, r, out);
    out.push_back(centroid + r * m);
    AppendArc(m, d_start, centroid, r, out);
  } else if (d_end.dot(d_start) < 1.0 - 1e-12) {
    AppendArc(d_end, d_start, centroid, r, out);
  } else {
    return out;  // both ends leave the same way: one far point closes the loop
  }
  out.push_back(centroid + r * d_start);
  return out;
}

}  // namespace snapthread::topology
