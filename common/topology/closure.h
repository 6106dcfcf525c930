// Closing an open polyline far away, so that a knot type is defined for it.
#pragma once

#include <span>
#include <vector>

#include <Eigen/Core>

namespace snapthread::topology {

// The standard closure: each end is carried radially away from the centroid (along the end
// tangent if an end sits on the centroid) to a sphere of three times the curve's radius
// about the centroid, and the two points are joined along that sphere. Every path on that
// sphere is isotopic to every other in the complement of the curve, so the knot type does
// not depend on which arc is taken. A planar curve's ends leave at 45 degrees out of its
// plane (to one side), so the closure never cuts the curve within that plane. The result is a closed polygon: its last vertex joins
// its first. Fewer than two nodes, or all nodes at one point, come back unchanged.
std::vector<Eigen::Vector3d> CloseFarAway(std::span<const Eigen::Vector3d> nodes);

}  // namespace snapthread::topology
