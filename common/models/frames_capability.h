// Material frames for drawing: a model with a frame on each edge (the rod's material
// director and twist) gives it to a viewer beside the node positions (the server's
// thread_shape_t.frames). Model::frames() gives it, null for a model whose shape is its
// nodes alone.
#pragma once

#include <Eigen/Core>

#include "numeric/types.h"

namespace snapthread {

class FramesCapability {
 public:
  virtual ~FramesCapability() = default;

  // The material director m1 of every edge (3 x edges, unit) into *d1 and the twist
  // density of every edge (rad per model length) into *twist_density, edge j joining
  // nodes j and j + 1 of NodePositions(). Either pointer may be null.
  virtual void MaterialFrames(const Vec& x, const Vec& u, Eigen::Matrix3Xd* d1, Vec* twist_density) const = 0;
};

}  // namespace snapthread
