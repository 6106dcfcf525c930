#include "linalg/banded_ldlt.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace snapthread {

LinearSolverStatus BandedLdlt::Analyze(const SparseMatrix& a) {
  factorized_ = false;
  pattern_.Clear();
  bandwidth_ = -1;
  if (!internal::ValidateForAnalysis(a, &message_)) {
    message_ = "banded: " + message_;
    return LinearSolverStatus::kInvalidInput;
  }
  n_ = static_cast<int>(a.cols());
  int b = 0;
  for (int j = 0; j < n_; ++j) {
    const int* rows = a.innerIndexPtr() + internal::ColumnBegin(a, j);
    for (int p = 0, count = internal::ColumnCount(a, j); p < count; ++p) {
      b = std::max(b, std::abs(rows[p] - j));
    }
  }
  bandwidth_ = b;
  pattern_.Assign(a);
  band_.setZero(b + 1, n_);
  message_.clear();
  return LinearSolverStatus::kSuccess;
}

LinearSolverStatus BandedLdlt::Factorize(const SparseMatrix& a) {
  factorized_ = false;
  if (pattern_.Empty()) {
    message_ = "banded: Factorize() before a successful Analyze()";
    return LinearSolverStatus::kInvalidInput;
  }
  if (!pattern_.Matches(a)) {
    message_ = "banded: the pattern differs from the analysed one";
    return LinearSolverStatus::kInvalidInput;
  }
  const int n = n_;
  const int b = bandwidth_;
  // Scatter the lower triangle: A(i,j), i >= j, goes to row (j - i + b) of column i.
  band_.setZero();
  for (int j = 0; j < n; ++j) {
    const int begin = internal::ColumnBegin(a, j);
    const int* rows = a.innerIndexPtr() + begin;
    const double* values = a.valuePtr() + begin;
    for (int p = 0, count = internal::ColumnCount(a, j); p < count; ++p) {
      if (rows[p] >= j) band_(j - rows[p] + b, rows[p]) = values[p];
    }
  }
  const double scale = internal::MaxAbsEntry(a);

  // Row-oriented (Doolittle) LDL^T. For row i, first u(i,j) = L(i,j) d_j for j < i:
  //   u(i,j) = a(i,j) - sum_{k<j} u(i,k) L(j,k),
  // then d_i = a(i,i) - sum_j u(i,j) L(i,j) and L(i,j) = u(i,j) / d_j. Rows i and j
  // are both contiguous in band_, so every inner loop is a contiguous dot product.
  double* data = band_.data();
  const int ld = b + 1;
  for (int i = 0; i < n; ++i) {
    double* ri = data + static_cast<std::ptrdiff_t>(i) * ld;  // ri[k - i + b] = L(i,k)
    const int k0 = std::max(0, i - b);
    for (int j = k0; j < i; ++j) {
      const double* rj = data + static_cast<std::ptrdiff_t>(j) * ld;
      const double* x = ri + (k0 - i + b);
      const double* y = rj + (k0 - j + b);
      double s = 0.0;
      for (int k = 0; k < j - k0; ++k) s += x[k] * y[k];
      ri[j - i + b] -= s;
    }
    double di = ri[b];
    for (int j = k0; j < i; ++j) {
      const double u = ri[j - i + b];
      const double l = u / data[static_cast<std::ptrdiff_t>(j) * ld + b];
      di -= u * l;
      ri[j - i + b] = l;
    }
    ri[b] = di;
    if (!std::isfinite(di) || std::abs(di) <= internal::kSingularPivotTolerance * scale) {
      // Later rows would divide by this pivot: stop here. The inertia is not defined.
      negative_pivots_ = 0;
      min_abs_pivot_ = std::abs(di);
      message_ = internal::PivotFailureMessage("banded", i, di, scale);
      return LinearSolverStatus::kNumericalIssue;
    }
  }
  const internal::PivotSummary pivots = internal::SummarizePivots(band_.row(b), n, scale);
  negative_pivots_ = pivots.negative;
  min_abs_pivot_ = pivots.min_abs;
  factorized_ = true;
  message_.clear();
  return LinearSolverStatus::kSuccess;
}

LinearSolverStatus BandedLdlt::Solve(const Vec& b_in, Vec* x) const {
  if (!factorized_) {
    return LinearSolverStatus::kInvalidInput;
  }
  if (x == nullptr || b_in.size() != n_ || x == &b_in) {
    return LinearSolverStatus::kInvalidInput;
  }
  const int n = n_;
  const int b = bandwidth_;
  const int ld = b + 1;
  const double* data = band_.data();
  *x = b_in;  // no allocation when x already has size n
  double* v = x->data();
  // L y = b (forward, row i of L is contiguous).
  for (int i = 0; i < n; ++i) {
    const double* ri = data + static_cast<std::ptrdiff_t>(i) * ld;
    const int k0 = std::max(0, i - b);
    double s = 0.0;
    for (int k = k0; k < i; ++k) s += ri[k - i + b] * v[k];
    v[i] -= s;
  }
  // D z = y.
  for (int i = 0; i < n; ++i) v[i] /= data[static_cast<std::ptrdiff_t>(i) * ld + b];
  // L^T x = z (backward, column-oriented: row i of L is column i of L^T).
  for (int i = n - 1; i > 0; --i) {
    const double* ri = data + static_cast<std::ptrdiff_t>(i) * ld;
    const int k0 = std::max(0, i - b);
    const double xi = v[i];
    for (int k = k0; k < i; ++k) v[k] -= ri[k - i + b] * xi;
  }
  return LinearSolverStatus::kSuccess;
}

}  // namespace snapthread
