// Triangle meshes for the 3-D scene (tube, spheres, arrows), built on the CPU each frame
// into one vertex array. No OpenGL here, so the geometry is testable without a context.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace snapthread::viewer {

struct Vertex {
  float position[3];
  float normal[3];  // zero normal = unlit (drawn in its flat colour)
  float color[3];
};

using Rgb = Eigen::Vector3f;

// Rotation-minimising frame of a polyline at each of its points: the unit tangent (central
// difference) and a unit normal carried from point to point by parallel transport (the
// rotation taking one tangent to the next), so it does not turn about the curve.
struct CurveFrame {
  Eigen::Vector3d tangent;
  Eigen::Vector3d normal;
  Eigen::Vector3d Binormal() const { return tangent.cross(normal); }
};
std::vector<CurveFrame> RotationMinimisingFrames(const std::vector<Eigen::Vector3d>& path);

// How a tube's surface is painted, ring by ring (one entry per path point).
struct TubePaint {
  // Ring i's vertex k sits at angle angle[i] + 2πk/sides from the frame's normal towards
  // its binormal (empty: 0 everywhere).
  std::vector<double> angle;
  std::vector<Rgb> color;  // per ring, blended along the tube
  // The faces within ±stripe_half_columns columns of vertex 0 (the direction `angle`)
  // are drawn flat in stripe_color: a band of ±stripe_half_columns·360°/sides (0: none).
  int stripe_half_columns = 0;
  Rgb stripe_color = Rgb::Zero();
};

class MeshBuilder {
 public:
  // Tube of `radius` along the polyline, rings of `sides` vertices oriented by parallel
  // transport (rotation-minimising frames), so the surface does not twist at bends.
  void AppendTube(const std::vector<Eigen::Vector3d>& path, double radius, int sides,
                  const Rgb& color);
  // The same tube with the rings turned and coloured by `paint` (frames: of `path`).
  void AppendPaintedTube(const std::vector<Eigen::Vector3d>& path,
                         const std::vector<CurveFrame>& frames, double radius, int sides,
                         const TubePaint& paint);
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
