// Continuous symmetries of a model's energy: one-parameter groups of rotations
// x -> S_k(t) x (period 2 pi) that leave E(., u) unchanged for controls on the rotation's
// axis and nearly so near it (a thread3d grasp on the clamp axis lets the thread roll
// about it at no cost). Their generators span null directions of E_xx there, along which
// Newton steps are singular and straight steps crawl round the circle; the solvers step
// in the complement and move along the orbit itself (solvers/symmetry_orbits.h).
// Model::symmetry() gives it, null for a model without such a symmetry.
#pragma once

#include "numeric/types.h"

namespace snapthread {

class SymmetryCapability {
 public:
  virtual ~SymmetryCapability() = default;

  // How many symmetries (>= 1).
  virtual int NumSymmetries() const = 0;
  // The generator d/dt S_k(t) x at t = 0, size NumStates(). k < NumSymmetries().
  virtual void SymmetryGenerator(int k, const Vec& x, const Vec& u, Vec* g) const = 0;
  // y = S_k(t) x (t in radians). k < NumSymmetries().
  virtual void ApplySymmetry(int k, double t, const Vec& x, const Vec& u, Vec* y) const = 0;
};

}  // namespace snapthread
