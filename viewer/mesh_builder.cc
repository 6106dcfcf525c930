#include "mesh_builder.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace snapthread::viewer {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Vector3d AnyPerpendicular(const Eigen::Vector3d& t) {
  const Eigen::Vector3d a =
      std::abs(t.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return t.cross(a).normalized();
}

}  // namespace

void MeshBuilder::Push(const Eigen::Vector3d& p, const Eigen::Vector3d& n, const Rgb& c) {
  Vertex v;
  for (int i = 0; i < 3; ++i) {
    v.position[i] = static_cast<float>(p[i]);
    v.normal[i] = static_cast<float>(n[i]);
    v.color[i] = c[i];
  }
  vertices_.push_back(v);
}

std::vector<CurveFrame> RotationMinimisingFrames(const std::vector<Eigen::Vector3d>& path) {
  const int m = static_cast<int>(path.size());
  std::vector<CurveFrame> frames(m);
  for (int i = 0; i < m; ++i) {
    const Eigen::Vector3d d = path[std::min(i + 1, m - 1)] - path[std::max(i - 1, 0)];
    frames[i].tangent = d.norm() > 0 ? d.normalized() : Eigen::Vector3d::UnitX();
  }
  if (m == 0) return frames;
  // Parallel transport of the normal: rotate it by the rotation taking t_{i-1} to t_i.
  frames[0].normal = AnyPerpendicular(frames[0].tangent);
  for (int i = 1; i < m; ++i) {
    const Eigen::Vector3d& t = frames[i].tangent;
    const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(frames[i - 1].tangent, t);
    Eigen::Vector3d n = q * frames[i - 1].normal;
    n -= n.dot(t) * t;
    frames[i].normal = n.norm() > 1e-9 ? n.normalized() : AnyPerpendicular(t);
  }
  return frames;
}

void MeshBuilder::AppendTube(const std::vector<Eigen::Vector3d>& path, double radius, int sides,
                             const Rgb& color) {
  TubePaint paint;
  paint.color.assign(path.size(), color);
  AppendPaintedTube(path, RotationMinimisingFrames(path), radius, sides, paint);
}

void MeshBuilder::AppendPaintedTube(const std::vector<Eigen::Vector3d>& path,
                                    const std::vector<CurveFrame>& frames, double radius,
                                    int sides, const TubePaint& paint) {
  const int m = static_cast<int>(path.size());
  if (m < 2 || sides < 3 || frames.size() != path.size() || paint.color.size() != path.size() ||
      (!paint.angle.empty() && paint.angle.size() != path.size())) {
    return;
  }
  auto ring = [&](int i, int k) {
    const double a = 2.0 * kPi * k / sides + (paint.angle.empty() ? 0.0 : paint.angle[i]);
    return Eigen::Vector3d(std::cos(a) * frames[i].normal + std::sin(a) * frames[i].Binormal());
  };
  const int band = std::clamp(paint.stripe_half_columns, 0, sides / 2);
  for (int i = 0; i + 1 < m; ++i) {
    for (int k = 0; k < sides; ++k) {
      // Column k spans vertices k .. k+1: within the band when k < band or k >= sides - band.
      const bool stripe = k < band || k >= sides - band;
      const Rgb& c0 = stripe ? paint.stripe_color : paint.color[i];
      const Rgb& c1 = stripe ? paint.stripe_color : paint.color[i + 1];
      const Eigen::Vector3d n00 = ring(i, k), n01 = ring(i, k + 1);
      const Eigen::Vector3d n10 = ring(i + 1, k), n11 = ring(i + 1, k + 1);
      Push(path[i] + radius * n00, n00, c0);
      Push(path[i + 1] + radius * n10, n10, c1);
      Push(path[i + 1] + radius * n11, n11, c1);
      Push(path[i] + radius * n00, n00, c0);
      Push(path[i + 1] + radius * n11, n11, c1);
      Push(path[i] + radius * n01, n01, c0);
    }
  }
}

void MeshBuilder::AppendSphere(const Eigen::Vector3d& centre, double radius, const Rgb& color) {
  constexpr int kStacks = 10;
  constexpr int kSlices = 16;
  auto point = [](int i, int j) {
    const double theta = kPi * i / kStacks;
    const double phi = 2.0 * kPi * j / kSlices;
    return Eigen::Vector3d(std::sin(theta) * std::cos(phi), std::cos(theta),
                           std::sin(theta) * std::sin(phi));
  };
  for (int i = 0; i < kStacks; ++i) {
    for (int j = 0; j < kSlices; ++j) {
      const Eigen::Vector3d a = point(i, j), b = point(i + 1, j), c = point(i + 1, j + 1),
                            d = point(i, j + 1);
      for (const Eigen::Vector3d* n : {&a, &b, &c, &a, &c, &d}) {
        Push(centre + radius * *n, *n, color);
      }
    }
  }
}

void MeshBuilder::AppendArrow(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                              double radius, const Rgb& color) {
  const Eigen::Vector3d d = to - from;
  const double length = d.norm();
  if (!(length > 1e-12)) return;
  const Eigen::Vector3d head_base = from + 0.8 * d;
  AppendTube({from, head_base}, radius, 12, color);
  // Cone: apex at `to`, base of 2.5 radii at head_base.
  const Eigen::Vector3d t = d / length;
  const Eigen::Vector3d n = AnyPerpendicular(t);
  const Eigen::Vector3d b = t.cross(n);
  constexpr int kSides = 16;
  const double r = 2.5 * radius;
  for (int k = 0; k < kSides; ++k) {
    const double a0 = 2.0 * kPi * k / kSides, a1 = 2.0 * kPi * (k + 1) / kSides;
    const Eigen::Vector3d r0 = std::cos(a0) * n + std::sin(a0) * b;
    const Eigen::Vector3d r1 = std::cos(a1) * n + std::sin(a1) * b;
    Push(head_base + r * r0, r0, color);
    Push(head_base + r * r1, r1, color);
    Push(to, (r0 + r1).normalized(), color);
    Push(head_base + r * r1, -t, color);
    Push(head_base + r * r0, -t, color);
    Push(head_base, -t, color);
  }
}

}  // namespace snapthread::viewer
