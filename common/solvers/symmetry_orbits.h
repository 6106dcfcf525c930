// Motion along a model's continuous symmetries (Model::NumSymmetries), for the snap
// minimiser. Where the grasp crosses a symmetry axis (a thread3d grasp crossing the clamp
// axis), the followed state turns from a minimum into a saddle along the generator and
// the new minimum lies half-way round the orbit. A Newton-type minimiser steps along
// straight lines: along a rotation each step leaves the circle, stretching the thread, so
// it crawls round it (hundreds of iterations). Here the orbit is searched on the circle
// itself — stepped, then refined — and the minimiser continues from there with Newton
// steps, whose quadratic model now holds (the rest of the state is the complement).
#pragma once

#include "models/model.h"

namespace snapthread {

class SymmetryOrbits {
 public:
  explicit SymmetryOrbits(const Model& model);
  bool empty() const { return model_.NumSymmetries() == 0; }
  // Moves x downhill along each symmetry orbit through it, as far as E keeps falling
  // (steps of 1/16 turn from t = 0 in the falling direction, the bottom refined by
  // golden section), when that lowers E beyond round-off. Returns true if x moved.
  bool MoveDownhill(const Vec& u, Vec* x);

 private:
  const Model& model_;
  Vec trial_, best_;
};

}  // namespace snapthread
