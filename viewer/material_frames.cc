#include "material_frames.h"

#include <algorithm>
#include <cmath>

namespace snapthread::viewer {

Rgb TwistColor(const Rgb& base, double twist, double full_scale) {
  if (!(full_scale > 0.0) || !std::isfinite(twist)) return base;
  const float v = static_cast<float>(std::clamp(twist / full_scale, -1.0, 1.0));
  const Rgb& hue = v > 0.0f ? kTwistPositiveColor : kTwistNegativeColor;
  return base + kTwistBlendMax * std::abs(v) * (hue - base);
}

double TwistFullScale(const std::vector<Eigen::Vector3d>& nodes) {
  double length = 0.0;
  for (size_t k = 1; k < nodes.size(); ++k) length += (nodes[k] - nodes[k - 1]).norm();
  return length > 0.0 ? 2.0 * 3.14159265358979323846 / length : 0.0;
}

MaterialRings InterpolateMaterialFrames(const std::vector<std::vector<double>>& frames,
                                        int samples_per_segment,
                                        const std::vector<CurveFrame>& curve) {
  MaterialRings rings;
  const int edges = static_cast<int>(frames.size());
  const int s = std::max(samples_per_segment, 1);
  const int m = static_cast<int>(curve.size());
  if (edges < 1 || m != edges * s + 1) return rings;
  // Each edge's station (ring index), its d1 angle (unwrapped) and twist.
  std::vector<int> station(edges);
  std::vector<double> angle(edges), twist(edges);
  for (int j = 0; j < edges; ++j) {
    if (frames[j].size() != 4) return rings;
    station[j] = j * s + s / 2;
    const CurveFrame& f = curve[station[j]];
    const Eigen::Vector3d d1(frames[j][0], frames[j][1], frames[j][2]);
    double a = std::atan2(d1.dot(f.Binormal()), d1.dot(f.normal));
    if (j > 0) a = angle[j - 1] + std::remainder(a - angle[j - 1], 2.0 * 3.14159265358979323846);
    angle[j] = a;
    twist[j] = frames[j][3];
  }
  rings.angle.resize(m);
  rings.twist.resize(m);
  int j = 0;  // the station at or before ring i
  for (int i = 0; i < m; ++i) {
    while (j + 1 < edges && station[j + 1] <= i) ++j;
    if (i <= station[0] || j + 1 >= edges) {
      const int e = i <= station[0] ? 0 : edges - 1;
      rings.angle[i] = angle[e];
      rings.twist[i] = twist[e];
      continue;
    }
    const double w = double(i - station[j]) / (station[j + 1] - station[j]);
    rings.angle[i] = (1.0 - w) * angle[j] + w * angle[j + 1];
    rings.twist[i] = (1.0 - w) * twist[j] + w * twist[j + 1];
  }
  return rings;
}

}  // namespace snapthread::viewer
