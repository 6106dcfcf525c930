// Shrinking a closed polygon without changing its knot type.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace snapthread::topology {

// Removes vertex v (joining its neighbours directly) whenever no other edge of the polygon
// pierces the triangle (prev, v, next): sliding the edge across an empty triangle is an
// isotopy (Koniaris and Muthukumar 1991; Taylor's reduction in KnotPlot). Repeats until no
// vertex can go. The test is conservative (edges that graze the triangle within a relative
// 1e-9 count as piercing), so it never changes the knot type; it may keep a few vertices
// that could go. Turns a many-crossing projection (a coiled rod) into a handful of
// crossings, and the diagram's cost with it. A uniform grid over the edges keeps a pass
// near O(n); edges longer than the grid allows are tested against every triangle.
void SimplifyClosedPolygon(std::vector<Eigen::Vector3d>& polygon);

}  // namespace snapthread::topology
