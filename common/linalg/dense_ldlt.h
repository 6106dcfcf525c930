// Dense symmetric LDL^T (Eigen::LDLT, diagonal pivoting: P^T L D L^T P) for small n,
// where a dense factorisation beats any sparse bookkeeping (see the measured rule in
// linear_solver.cc). The sparse values are copied into a dense matrix preallocated in
// Analyze(), and Eigen's LDLT is preallocated for n there too, so Factorize() and
// Solve() do not allocate after Analyze() (Solve() only if *x has the wrong size).
//
// Eigen's LDLT uses 1x1 diagonal pivots only (no Bunch-Kaufman 2x2 blocks): an
// indefinite matrix whose remaining diagonal is all zero (e.g. [[0,1],[1,0]]) gets a
// zero pivot and is reported as kNumericalIssue, like a singular one.
#pragma once

#include <optional>
#include <string_view>

#include <Eigen/Cholesky>

#include "linalg/ldlt_support.h"
#include "linalg/linear_solver.h"

namespace snapthread {

class DenseLdlt final : public SymmetricLinearSolver {
 public:
  // Beyond this n the dense copy (8 n^2 bytes) is refused in Analyze(): 4096^2 doubles
  // are 128 MiB, and the sparse backends win long before (linear_solver.cc).
  static constexpr int kMaxSize = 4096;

  std::string_view Name() const override { return "dense"; }
  LinearSolverStatus Analyze(const SparseMatrix& a) override;
  LinearSolverStatus Factorize(const SparseMatrix& a) override;
  LinearSolverStatus Solve(const Vec& b, Vec* x) const override;

 private:
  internal::PatternCopy pattern_;
  int n_ = 0;
  Mat dense_;  // lower triangle of A (the upper one is never read)
  // Emplaced with the size in Analyze() (LDLT's preallocating constructor; constructed in
  // place because copying it would read its not-yet-initialised info member).
  std::optional<Eigen::LDLT<Mat, Eigen::Lower>> ldlt_;
  bool factorized_ = false;
};

}  // namespace snapthread
