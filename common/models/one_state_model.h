// What the one-variable models (zeeman: θ, cusp: T) share: a 1 x 1 Hessian pattern,
// the state itself as the sweep's probe, and no band to speak of.
#pragma once

#include "models/model.h"

namespace snapthread::internal {

class OneStateModel : public Model {
 public:
  OneStateModel() {
    pattern_.resize(1, 1);
    pattern_.insert(0, 0) = 0.0;
    pattern_.makeCompressed();
  }
  int NumStates() const override { return 1; }
  const SparseMatrix& HessianPattern() const override { return pattern_; }
  double Probe(const Vec& x, const Vec&) const override { return x[0]; }
  int HessianBandwidth() const override { return 0; }

 protected:
  // h with the 1 x 1 pattern (reallocated only when it has another shape).
  void ShapeHessian(SparseMatrix* h) const {
    if (h->rows() != 1 || h->cols() != 1 || h->nonZeros() != 1) *h = pattern_;
  }

 private:
  SparseMatrix pattern_;
};

}  // namespace snapthread::internal
