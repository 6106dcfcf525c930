// Triangle meshes for the 3-D scene (tube, spheres, arrows), built on the CPU each frame
// into one vertex array. No OpenGL here, so the geometry is testable without a context.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace snapthread::viewer {

struct Vertex {
  float position[3];
  float normal[3];  // zero normal = unlit (drawn in its flat colour)
  float color[3];
};

using Rgb = Eigen::Vector3f;

class MeshBuilder {
 public:
  // Tube of `radius` along the polyline, rings of `sides` vertices oriented by parallel
  // transport (rotation-minimising frames), so the surface does not twist at bends.
  void AppendTube(const std::vector<Eigen::Vector3d>& path, double radius, int sides,
                  const Rgb& color);
  void AppendSphere(const Eigen::Vector3d& centre, double radius, const Rgb& color);
  // Arrow from `from` to `to`: shaft of `radius`, cone head a fifth of the length.
  void AppendArrow(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double radius,
                   const Rgb& color);
  void Clear() { vertices_.clear(); }
  const std::vector<Vertex>& vertices() const { return vertices_; }

 private:
  void Push(const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Rgb& c);
  std::vector<Vertex> vertices_;
};

}  // namespace snapthread::viewer
