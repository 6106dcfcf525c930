#include "spline.h"

#include <algorithm>
#include <cmath>

namespace snapthread::viewer {
namespace {

// Knot spacing |p_i+1 - p_i|^(1/2) (centripetal); a floor keeps coincident nodes finite.
double KnotStep(const Point3& a, const Point3& b) {
  return std::max(std::sqrt((b - a).norm()), 1e-9);
}

// Barry–Goldman pyramid for the non-uniform Catmull-Rom segment p1 -> p2.
Point3 Segment(const Point3& p0, const Point3& p1, const Point3& p2, const Point3& p3,
               double t) {
  const double t0 = 0.0;
  const double t1 = t0 + KnotStep(p0, p1);
  const double t2 = t1 + KnotStep(p1, p2);
  const double t3 = t2 + KnotStep(p2, p3);
  const double u = t1 + t * (t2 - t1);
  const Point3 a1 = (t1 - u) / (t1 - t0) * p0 + (u - t0) / (t1 - t0) * p1;
  const Point3 a2 = (t2 - u) / (t2 - t1) * p1 + (u - t1) / (t2 - t1) * p2;
  const Point3 a3 = (t3 - u) / (t3 - t2) * p2 + (u - t2) / (t3 - t2) * p3;
  const Point3 b1 = (t2 - u) / (t2 - t0) * a1 + (u - t0) / (t2 - t0) * a2;
  const Point3 b2 = (t3 - u) / (t3 - t1) * a2 + (u - t1) / (t3 - t1) * a3;
  return (t2 - u) / (t2 - t1) * b1 + (u - t1) / (t2 - t1) * b2;
}

}  // namespace

std::vector<Point3> CatmullRomCurve(const std::vector<Point3>& nodes, int samples_per_segment) {
  const int n = static_cast<int>(nodes.size());
  if (n < 2) return nodes;
  samples_per_segment = std::max(samples_per_segment, 1);
  std::vector<Point3> out;
  out.reserve(static_cast<size_t>((n - 1) * samples_per_segment + 1));
  for (int i = 0; i + 1 < n; ++i) {
    const Point3& p1 = nodes[i];
    const Point3& p2 = nodes[i + 1];
    // Phantom end points mirror the neighbour, so the end tangents follow the end segments.
    const Point3 p0 = i > 0 ? nodes[i - 1] : Point3(2.0 * p1 - p2);
    const Point3 p3 = i + 2 < n ? nodes[i + 2] : Point3(2.0 * p2 - p1);
    for (int k = 0; k < samples_per_segment; ++k) {
      out.push_back(Segment(p0, p1, p2, p3, double(k) / samples_per_segment));
    }
  }
  out.push_back(nodes.back());
  return out;
}

}  // namespace snapthread::viewer
