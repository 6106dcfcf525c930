#include "solvers/eigen_tracking.h"

#include <cmath>

namespace snapthread {

void SmallestEigenpair::Resize(int n) {
  if (v_.size() != n) {
    v_.resize(n);
    w_.resize(n);
    initialized_ = false;
  }
}

void SmallestEigenpair::Reset() { initialized_ = false; }

void SmallestEigenpair::EnsureInitialized(int n) {
  Resize(n);
  if (!initialized_) {
    // A deterministic start with components on every mode of a chain.
    for (int i = 0; i < n; ++i) v_[i] = 1.0 + 0.37 * std::sin(1.0 + 3.1 * i);
    v_.normalize();
    initialized_ = true;
  }
}

double SmallestEigenpair::Update(const SymmetricLinearSolver& factor, const SparseMatrix& h,
                                 int iterations) {
  EnsureInitialized(static_cast<int>(h.rows()));
  for (int k = 0; k < iterations; ++k) {
    if (factor.Solve(v_, &w_) != LinearSolverStatus::kSuccess) break;
    const double norm = w_.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) break;
    v_ = w_ / norm;
  }
  w_.noalias() = h * v_;  // Rayleigh quotient
  lambda_ = v_.dot(w_);
  return lambda_;
}

}  // namespace snapthread
