// Smallest eigenpair of a factorised symmetric matrix by inverse iteration, warm-started
// from the previous eigenvector (§2.4: "we track the condition of the Hessian"). With
// the LDL^T factor already computed for the Newton step, each iteration is one solve:
// O(n) for a chain.
#pragma once

#include "linalg/linear_solver.h"
#include "numeric/types.h"

namespace snapthread {

class SmallestEigenpair {
 public:
  void Resize(int n);
  // Runs `iterations` steps of inverse iteration with `factor` (a factorisation of h)
  // and returns the Rayleigh quotient of the unit vector v, taken from the last solve
  // (w = H^-1 v gives w^T H w = w^T v: no product with H; H is used only by the
  // fallback when no step succeeds). Inverse iteration
  // converges to the eigenvalue of smallest modulus, which is the smallest eigenvalue
  // wherever H is positive definite or has one slightly negative eigenvalue — the
  // situations near a fold where it matters.
  double Update(const SymmetricLinearSolver& factor, const SparseMatrix& h, int iterations);
  // The same steps without the fallback: false when no step succeeded (a failed solve,
  // iterations < 1), and then value() is not updated. Needs no H.
  bool Iterate(const SymmetricLinearSolver& factor, int n, int iterations);
  const Vec& vector() const { return v_; }
  bool initialized() const { return initialized_; }
  double value() const { return lambda_; }
  void Reset();
  // Sets the deterministic start vector if no eigenvector has been tracked yet.
  void EnsureInitialized(int n);

 private:
  Vec v_, w_;
  double lambda_ = 0.0;
  bool initialized_ = false;
};

}  // namespace snapthread
