// A knot diagram: a closed polygon's projection onto a plane, with its crossings.
#pragma once

#include <span>
#include <vector>

#include <Eigen/Core>

namespace snapthread::topology {

struct Crossing {
  int over_edge = 0;       // edge i runs from vertex i to vertex i+1 (mod n)
  double over_param = 0;   // where along it, in (0, 1)
  int under_edge = 0;
  double under_param = 0;
  int sign = 0;            // +1 or -1 (a fixed handedness; the mirror flips every sign)
};

struct Diagram {
  std::vector<Crossing> crossings;
  int num_edges = 0;
  // False when the projection is not generic: two edges overlap, a crossing falls on a
  // vertex, or the strands at a crossing are at one depth (relative 1e-9). Pick another
  // direction then.
  bool generic = true;
};

// Projects the closed polygon along `direction` (any nonzero vector) and lists every
// crossing. Candidate edge pairs come from a sweep over the projected edges' x-intervals,
// so the cost is O(n log n + pairs whose x-intervals overlap).
Diagram ProjectDiagram(std::span<const Eigen::Vector3d> polygon,
                       const Eigen::Vector3d& direction);

}  // namespace snapthread::topology
