// Motion along a model's continuous symmetries (SymmetryCapability), for the snap
// minimiser. Where the grasp crosses a symmetry axis (a thread3d grasp crossing the clamp
// axis), the followed state turns from a minimum into a saddle along the generator and
// the new minimum lies half-way round the orbit. A Newton-type minimiser steps along
// straight lines: along a rotation each step leaves the circle, stretching the thread, so
// it crawls round it (hundreds of iterations). Here the orbit is searched on the circle
// itself — stepped, then refined — and the minimiser continues from there with Newton
// steps, whose quadratic model now holds (the rest of the state is the complement).
#pragma once

#include "models/contact_capability.h"
#include "models/model.h"
#include "models/symmetry_capability.h"

namespace snapthread {

class SymmetryOrbits {
 public:
  explicit SymmetryOrbits(const Model& model);
  // The model has no symmetry: MoveDownhill has nothing to do.
  bool empty() const { return symmetry_ == nullptr; }
  // Moves x downhill along each symmetry orbit through it, as far as E keeps falling
  // (steps of 1/16 turn from t = 0 in the falling direction, the bottom refined by
  // golden section), when that lowers E beyond round-off. Returns true if x moved.
  bool MoveDownhill(const Vec& u, Vec* x);

 private:
  const Model& model_;
  // Asked once: the symmetries, and self-contact for the jump's collision check (null: none).
  const SymmetryCapability* const symmetry_;
  const ContactCapability* const contact_;
  Vec trial_, best_;
};

}  // namespace snapthread
