#include "linalg/dense_ldlt.h"

#include <string>

namespace snapthread {

LinearSolverStatus DenseLdlt::Analyze(const SparseMatrix& a) {
  factorized_ = false;
  pattern_.Clear();
  if (!internal::ValidateForAnalysis(a, &message_)) {
    message_ = "dense: " + message_;
    return LinearSolverStatus::kInvalidInput;
  }
  if (a.rows() > kMaxSize) {
    message_ = "dense: n = " + std::to_string(a.rows()) + " exceeds the dense limit " +
               std::to_string(kMaxSize) + " (use \"cholmod\" or \"banded\")";
    return LinearSolverStatus::kInvalidInput;
  }
  n_ = static_cast<int>(a.rows());
  pattern_.Assign(a);
  dense_.setZero(n_, n_);
  ldlt_.emplace(n_);  // preallocates the factor, transpositions and work vector
  message_.clear();
  return LinearSolverStatus::kSuccess;
}

LinearSolverStatus DenseLdlt::Factorize(const SparseMatrix& a) {
  factorized_ = false;
  if (pattern_.Empty()) {
    message_ = "dense: Factorize() before a successful Analyze()";
    return LinearSolverStatus::kInvalidInput;
  }
  if (!pattern_.Matches(a)) {
    message_ = "dense: the pattern differs from the analysed one";
    return LinearSolverStatus::kInvalidInput;
  }
  // Lower triangle only; entries outside the pattern stay zero from Analyze().
  for (int j = 0; j < n_; ++j) {
    const int begin = internal::ColumnBegin(a, j);
    const int* rows = a.innerIndexPtr() + begin;
    const double* values = a.valuePtr() + begin;
    for (int p = 0, count = internal::ColumnCount(a, j); p < count; ++p) {
      if (rows[p] >= j) dense_(rows[p], j) = values[p];
    }
  }
  ldlt_->compute(dense_);
  const double scale = internal::MaxAbsEntry(a);
  const internal::PivotSummary pivots = internal::SummarizePivots(ldlt_->vectorD(), n_, scale);
  negative_pivots_ = pivots.negative;
  min_abs_pivot_ = pivots.min_abs;
  if (pivots.first_bad >= 0 || ldlt_->info() != Eigen::Success) {
    // Eigen's LDLT stops pivoting once the remaining diagonal is below its own tolerance;
    // either way a (relative) zero pivot means singular to working precision.
    const int i = pivots.first_bad >= 0 ? pivots.first_bad : 0;
    message_ = internal::PivotFailureMessage("dense", i, ldlt_->vectorD()(i), scale);
    return LinearSolverStatus::kNumericalIssue;
  }
  factorized_ = true;
  message_.clear();
  return LinearSolverStatus::kSuccess;
}

LinearSolverStatus DenseLdlt::Solve(const Vec& b, Vec* x) const {
  if (!factorized_ || x == nullptr || x == &b || b.size() != n_) {
    return LinearSolverStatus::kInvalidInput;
  }
  x->resize(n_);
  *x = ldlt_->solve(b);
  return LinearSolverStatus::kSuccess;
}

}  // namespace snapthread
