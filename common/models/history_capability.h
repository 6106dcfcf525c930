// Lagged model data: a model whose energy is written against data of the last accepted
// state (the rod's time-parallel reference frames, docs/models-rod.md) moves that data
// when the tracker accepts an equilibrium. At x itself E and the equilibrium do not
// change. Model::history() gives it, null for a model whose energy depends on (x, u)
// alone (zeeman, cusp, curve2d, thread3d): then there is nothing to move.
#pragma once

#include "numeric/types.h"

namespace snapthread {

class HistoryCapability {
 public:
  virtual ~HistoryCapability() = default;

  // Called by the tracker after it accepted the equilibrium x at controls u (after the
  // force and stiffness of that update were computed): the lagged data move to it.
  virtual void AcceptState(const Vec& x, const Vec& u) = 0;
  // Called by the tracker's Reset and Resume before it starts again: forget the lagged
  // data, so the model is the one a fresh model would be (the rod untwists: its grasp
  // turn count goes back to the rest frames').
  virtual void ResetHistory() = 0;
};

}  // namespace snapthread
