// Helpers shared by the LDL^T backends (private to libsnapthread_core): pattern copies
// for the "pattern differs from the analysed one" check, input validation and the
// singularity test on the pivots of D. Header-only on purpose: it is three small
// classes' common plumbing, not a concept of its own.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "linalg/linear_solver.h"
#include "numeric/types.h"

namespace snapthread::internal {

// A pivot |d_ii| <= kSingularPivotTolerance * max_ij |a_ij| means "singular to working
// precision". The max-abs entry is a cheap stand-in for ||A||; 1e-14 is ~50 eps: a
// round-off zero of a small matrix falls below it, the smallest pivot of a merely
// ill-conditioned Hessian near a fold (where the solvers still need the factor for
// inverse iteration) stays above it. It is a heuristic, not a rank test: an exact zero
// pivot is always caught, but a matrix singular only up to round-off can leave a pivot
// well above it (random 6x6 Q diag(0, ...) Q^T: relative pivots up to ~1e-11, ~4% not
// flagged, measured with all three backends), and then Solve() returns huge values.
inline constexpr double kSingularPivotTolerance = 1e-14;

// Number of stored entries of column j and where they start, for compressed and
// uncompressed Eigen matrices alike.
inline int ColumnBegin(const SparseMatrix& a, int j) { return a.outerIndexPtr()[j]; }
inline int ColumnCount(const SparseMatrix& a, int j) {
  return a.isCompressed() ? a.outerIndexPtr()[j + 1] - a.outerIndexPtr()[j]
                          : a.innerNonZeroPtr()[j];
}

// A compressed-column copy of a sparsity pattern. Assign() allocates; Matches() does not.
class PatternCopy {
 public:
  void Assign(const SparseMatrix& a) {
    const int n = static_cast<int>(a.cols());
    rows_ = static_cast<int>(a.rows());
    outer_.assign(n + 1, 0);
    inner_.clear();
    inner_.reserve(static_cast<size_t>(a.nonZeros()));
    for (int j = 0; j < n; ++j) {
      const int* begin = a.innerIndexPtr() + ColumnBegin(a, j);
      inner_.insert(inner_.end(), begin, begin + ColumnCount(a, j));
      outer_[j + 1] = static_cast<int>(inner_.size());
    }
  }
  void Clear() {
    rows_ = 0;
    outer_.clear();
    inner_.clear();
  }
  bool Empty() const { return outer_.empty(); }
  int cols() const { return outer_.empty() ? 0 : static_cast<int>(outer_.size()) - 1; }
  int rows() const { return rows_; }
  int nonzeros() const { return inner_.empty() ? 0 : outer_.back(); }
  const std::vector<int>& outer() const { return outer_; }
  const std::vector<int>& inner() const { return inner_; }

  bool Matches(const SparseMatrix& a) const {
    if (Empty() || a.rows() != rows_ || a.cols() != cols() || a.nonZeros() != nonzeros()) {
      return false;
    }
    if (a.isCompressed()) {  // two contiguous comparisons (the per-step case)
      return std::equal(outer_.begin(), outer_.end(), a.outerIndexPtr()) &&
             std::equal(inner_.begin(), inner_.end(), a.innerIndexPtr());
    }
    for (int j = 0; j < cols(); ++j) {
      const int count = ColumnCount(a, j);
      if (count != outer_[j + 1] - outer_[j]) return false;
      const int* begin = a.innerIndexPtr() + ColumnBegin(a, j);
      if (!std::equal(begin, begin + count, inner_.begin() + outer_[j])) return false;
    }
    return true;
  }

 private:
  int rows_ = 0;
  std::vector<int> outer_;
  std::vector<int> inner_;
};

// Analyze()-time checks shared by all backends: square, non-empty, rows sorted within
// columns and a structurally symmetric pattern (the interface stores both triangles;
// each backend reads only the lower one, so a one-triangle input would silently
// factorise a different matrix). Allocates (a transpose); never called from Factorize().
inline bool ValidateForAnalysis(const SparseMatrix& a, std::string* message) {
  if (a.rows() != a.cols()) {
    *message = "matrix is not square (" + std::to_string(a.rows()) + " x " +
               std::to_string(a.cols()) + ")";
    return false;
  }
  if (a.rows() == 0) {
    *message = "matrix is empty";
    return false;
  }
  const int n = static_cast<int>(a.cols());
  for (int j = 0; j < n; ++j) {
    const int* begin = a.innerIndexPtr() + ColumnBegin(a, j);
    const int count = ColumnCount(a, j);
    for (int p = 0; p < count; ++p) {
      if (begin[p] < 0 || begin[p] >= n || (p > 0 && begin[p] <= begin[p - 1])) {
        *message = "row indices of column " + std::to_string(j) +
                   " are out of range, unsorted or duplicated";
        return false;
      }
    }
  }
  PatternCopy pattern, transposed;
  pattern.Assign(a);
  SparseMatrix at = a.transpose();
  at.makeCompressed();
  transposed.Assign(at);
  if (pattern.outer() != transposed.outer() || pattern.inner() != transposed.inner()) {
    *message = "pattern is not structurally symmetric (store both triangles)";
    return false;
  }
  return true;
}

// max_ij |a_ij| over the stored entries (the scale for kSingularPivotTolerance).
inline double MaxAbsEntry(const SparseMatrix& a) {
  double m = 0.0;
  for (int j = 0; j < a.outerSize(); ++j) {
    const double* v = a.valuePtr() + ColumnBegin(a, j);
    for (int p = 0, count = ColumnCount(a, j); p < count; ++p) m = std::max(m, std::abs(v[p]));
  }
  return m;
}

// Inertia and singularity from the diagonal d of D (Sylvester's law: the signs of the
// pivots of A = L D L^T are the signs of A's eigenvalues).
struct PivotSummary {
  int negative = 0;
  double min_abs = std::numeric_limits<double>::infinity();
  int first_bad = -1;  // first index with a zero (relative) or non-finite pivot, else -1
};
template <typename Pivots>
PivotSummary SummarizePivots(const Pivots& d, int n, double scale) {
  PivotSummary s;
  const double threshold = kSingularPivotTolerance * scale;
  for (int i = 0; i < n; ++i) {
    const double di = d(i);
    if (!std::isfinite(di) || std::abs(di) <= threshold) {
      if (s.first_bad < 0) s.first_bad = i;
    }
    if (di < 0.0) ++s.negative;
    s.min_abs = std::min(s.min_abs, std::abs(di));
  }
  return s;
}

// "zero pivot" message, built only on the failure path (allocates).
inline std::string PivotFailureMessage(std::string_view backend, int index, double pivot,
                                       double scale) {
  char text[200];
  if (std::isfinite(pivot)) {
    std::snprintf(text, sizeof(text),
                  ": pivot %d is zero to working precision (|d| = %.3g <= %.0e * max|a_ij| "
                  "= %.3g): the matrix is singular",
                  index, std::abs(pivot), kSingularPivotTolerance,
                  kSingularPivotTolerance * scale);
  } else {
    std::snprintf(text, sizeof(text), ": pivot %d is not finite (%g)", index, pivot);
  }
  return std::string(backend) + text;
}

}  // namespace snapthread::internal
