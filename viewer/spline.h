// Smooth curve through the thread's nodes for rendering. The seed draws the thread with a
// cubic spline through the nodes; we use the centripetal Catmull-Rom cubic (interpolates
// every node, C1, and never overshoots into loops or cusps between unevenly spaced nodes).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace snapthread::viewer {

using Point3 = Eigen::Vector3d;

// Samples the curve through `nodes`: `samples_per_segment` points per segment, the first
// node first and the last node last. Fewer than two nodes are returned unchanged.
std::vector<Point3> CatmullRomCurve(const std::vector<Point3>& nodes, int samples_per_segment);

}  // namespace snapthread::viewer
