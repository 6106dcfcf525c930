#include "linalg/banded_ldlt.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace snapthread {
namespace {

// The kernels below implement the row-oriented (Doolittle) LDL^T of the file comment.
// For row i, first u(i,j) = L(i,j) d_j for j < i:
//   u(i,j) = a(i,j) - sum_{k<j} u(i,k) L(j,k),
// then d_i = a(i,i) - sum_j u(i,j) L(i,j) and L(i,j) = u(i,j) / d_j. Rows i and j are
// both contiguous in the band, so every inner loop is a contiguous dot product.
//
// Each kernel comes twice: for any bandwidth (rows near the top, where the band is cut
// off, and bandwidths without a specialisation) and for a bandwidth B fixed at compile
// time on rows with a full band, where the loops unroll completely (a factorisation of a
// thread3d Hessian, B = 8, takes 2.7x fewer instructions, measured with callgrind). Both
// do the same operations in the same order, so the factor and the solutions are the same
// to the last bit whichever runs.

// Row i of the factorisation, band cut off at column k0 = max(0, i - b). Returns d_i.
inline double FactorRow(double* data, int i, int b) {
  const int ld = b + 1;
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
  return di;
}

// Row i >= B with the full band of a compile-time B: FactorRow() unrolled.
template <int B>
inline double FactorFullRow(double* data, int i) {
  constexpr int ld = B + 1;
  double* ri = data + static_cast<std::ptrdiff_t>(i) * ld;
  const double* r0 = ri - B * ld;  // row i - B
#pragma GCC unroll 32
  for (int j = 0; j < B; ++j) {
    const double* rj = r0 + j * ld;  // row i - B + j; L(i-B+j, i-B+k) = rj[B - j + k]
    double s = 0.0;
#pragma GCC unroll 32
    for (int k = 0; k < j; ++k) s += ri[k] * rj[B - j + k];
    ri[j] -= s;
  }
  double di = ri[B];
#pragma GCC unroll 32
  for (int j = 0; j < B; ++j) {
    const double u = ri[j];
    const double l = u / r0[j * ld + B];
    di -= u * l;
    ri[j] = l;
  }
  ri[B] = di;
  return di;
}

// Factorises rows 0..n-1 in place; returns the first row whose pivot is not finite or
// |d| <= threshold (then *pivot is it), or -1. B = 0: no specialisation.
template <int B>
int FactorBand(double* data, int n, int b, double threshold, double* pivot) {
  for (int i = 0; i < n; ++i) {
    const double di = (B > 0 && i >= B) ? FactorFullRow<B>(data, i) : FactorRow(data, i, b);
    if (!std::isfinite(di) || std::abs(di) <= threshold) {
      *pivot = di;
      return i;
    }
  }
  return -1;
}

// x = A^-1 x for m right-hand sides (columns of v, leading dimension `stride`): L y = b
// forward (row i of L is contiguous), D z = y, L^T x = z backward (column-oriented: row
// i of L is column i of L^T). Each column sees the operations of a single solve.
template <int B>
void SolveBand(const double* data, int n, int b, double* v, int m, std::ptrdiff_t stride) {
  const int ld = b + 1;
  // Rows 0 .. head-1 have a band cut off by the matrix' edge (every row without a
  // compile-time B); rows head .. n-1 have the full band of B.
  const int head = B > 0 ? std::min(B, n) : n;
  // Leading rows where every right-hand side is zero stay zero in L y = b (each of their
  // dot products is a sum of zeros): the forward sweep starts at the first non-zero.
  // E_xu's columns are zero but for the few nodes next to the grasp, the chain's last.
  int first = n;
  for (int c = 0; c < m; ++c) {
    const double* vc = v + c * stride;
    int k = 0;
    while (k < first && vc[k] == 0.0) ++k;
    first = k;
  }
  for (int i = first; i < head; ++i) {
    const double* ri = data + static_cast<std::ptrdiff_t>(i) * ld;
    for (int c = 0; c < m; ++c) {
      double* vc = v + c * stride;
      double s = 0.0;
      for (int k = std::max(0, i - b); k < i; ++k) s += ri[k - i + b] * vc[k];
      vc[i] -= s;
    }
  }
  if constexpr (B > 0) {
    for (int i = std::max(head, first); i < n; ++i) {
      const double* ri = data + static_cast<std::ptrdiff_t>(i) * (B + 1);
      for (int c = 0; c < m; ++c) {
        double* xc = v + c * stride + (i - B);  // xc[B] is row i
        double s = 0.0;
#pragma GCC unroll 32
        for (int k = 0; k < B; ++k) s += ri[k] * xc[k];
        xc[B] -= s;
      }
    }
  }
  for (int c = 0; c < m; ++c) {
    double* vc = v + c * stride;
    for (int i = 0; i < n; ++i) vc[i] /= data[static_cast<std::ptrdiff_t>(i) * ld + b];
  }
  if constexpr (B > 0) {
    for (int i = n - 1; i >= head; --i) {
      const double* ri = data + static_cast<std::ptrdiff_t>(i) * (B + 1);
      for (int c = 0; c < m; ++c) {
        double* xc = v + c * stride + (i - B);
        const double xi = xc[B];
#pragma GCC unroll 32
        for (int k = 0; k < B; ++k) xc[k] -= ri[k] * xi;
      }
    }
  }
  for (int i = std::min(head, n) - 1; i > 0; --i) {
    const double* ri = data + static_cast<std::ptrdiff_t>(i) * ld;
    for (int c = 0; c < m; ++c) {
      double* vc = v + c * stride;
      const double xi = vc[i];
      for (int k = std::max(0, i - b); k < i; ++k) vc[k] -= ri[k - i + b] * xi;
    }
  }
}

// The bandwidths with an unrolled kernel: chains have small, fixed bands (curve2d 2-5,
// thread3d 8, with a grip direction up to 10).
template <template <int> class Kernel, typename... Args>
auto ForBandwidth(int b, Args&&... args) {
  switch (b) {
    case 1: return Kernel<1>::Run(args...);
    case 2: return Kernel<2>::Run(args...);
    case 3: return Kernel<3>::Run(args...);
    case 4: return Kernel<4>::Run(args...);
    case 5: return Kernel<5>::Run(args...);
    case 6: return Kernel<6>::Run(args...);
    case 7: return Kernel<7>::Run(args...);
    case 8: return Kernel<8>::Run(args...);
    case 9: return Kernel<9>::Run(args...);
    case 10: return Kernel<10>::Run(args...);
    case 11: return Kernel<11>::Run(args...);
    case 12: return Kernel<12>::Run(args...);
    default: return Kernel<0>::Run(args...);
  }
}
template <int B>
struct FactorKernel {
  static int Run(double* data, int n, int b, double threshold, double* pivot) {
    return FactorBand<B>(data, n, b, threshold, pivot);
  }
};
template <int B>
struct SolveKernel {
  static int Run(const double* data, int n, int b, double* v, int m, std::ptrdiff_t stride) {
    SolveBand<B>(data, n, b, v, m, stride);
    return 0;
  }
};

}  // namespace

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
  // Scatter map and holes: A(i, j), i >= j, lives in row (j - i + b) of column i.
  const int ld = b + 1;
  std::vector<char> filled(static_cast<size_t>(ld) * n_, 0);
  scatter_.clear();
  for (int j = 0; j < n_; ++j) {
    for (int p = pattern_.outer()[j]; p < pattern_.outer()[j + 1]; ++p) {
      const int i = pattern_.inner()[p];
      if (i < j) continue;
      const int slot = i * ld + (j - i + b);
      scatter_.push_back({p, slot});
      filled[slot] = 1;
    }
  }
  holes_.clear();
  for (int i = 0; i < n_; ++i) {
    for (int j = std::max(0, i - b); j <= i; ++j) {
      const int slot = i * ld + (j - i + b);
      if (!filled[slot]) holes_.push_back(slot);
    }
  }
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
  // Scatter the lower triangle: A(i,j), i >= j, goes to row (j - i + b) of column i;
  // the slots the pattern leaves empty are cleared (the last factor's fill-in).
  double* data = band_.data();
  for (const int slot : holes_) data[slot] = 0.0;
  double scale = 0.0;  // max |a_ij| over the lower triangle (A is symmetric)
  if (a.isCompressed()) {
    const double* values = a.valuePtr();
    for (const Scatter& e : scatter_) {
      const double v = values[e.value];
      data[e.slot] = v;
      scale = std::max(scale, std::abs(v));
    }
  } else {
    for (int j = 0; j < n; ++j) {
      const int begin = internal::ColumnBegin(a, j);
      const int* rows = a.innerIndexPtr() + begin;
      const double* values = a.valuePtr() + begin;
      for (int p = 0, count = internal::ColumnCount(a, j); p < count; ++p) {
        if (rows[p] < j) continue;
        band_(j - rows[p] + b, rows[p]) = values[p];
        scale = std::max(scale, std::abs(values[p]));
      }
    }
  }

  return FactorInPlace(scale);
}

double* BandedLdlt::AssemblyBand(int* bandwidth) {
  if (pattern_.Empty()) return nullptr;
  factorized_ = false;
  if (bandwidth != nullptr) *bandwidth = bandwidth_;
  return band_.data();
}

LinearSolverStatus BandedLdlt::FactorizeAssembled() {
  factorized_ = false;
  if (pattern_.Empty()) {
    message_ = "banded: FactorizeAssembled() before a successful Analyze()";
    return LinearSolverStatus::kInvalidInput;
  }
  double* data = band_.data();
  for (const int slot : holes_) data[slot] = 0.0;
  // max |a_ij| over the pattern's lower triangle, as Factorize() takes it (the holes are
  // 0 and the slots outside the matrix, in the first b rows, are not the matrix').
  const int n = n_;
  const int b = bandwidth_;
  const int ld = b + 1;
  double scale = 0.0;
  for (int i = 0; i < std::min(b, n); ++i) {
    for (int j = std::max(0, i - b); j <= i; ++j) scale = std::max(scale, std::abs(data[i * ld + j - i + b]));
  }
  const double* rest = data + static_cast<std::ptrdiff_t>(std::min(b, n)) * ld;
  const std::ptrdiff_t count = static_cast<std::ptrdiff_t>(n - std::min(b, n)) * ld;
  // Four running maxima (the order of a max does not change it): independent chains
  // the compiler can pair up, instead of one serial dependency through 27 k entries.
  double m[4] = {scale, 0.0, 0.0, 0.0};
  std::ptrdiff_t k = 0;
  for (; k + 4 <= count; k += 4) {
    for (int q = 0; q < 4; ++q) m[q] = std::max(m[q], std::abs(rest[k + q]));
  }
  for (; k < count; ++k) m[0] = std::max(m[0], std::abs(rest[k]));
  scale = std::max(std::max(m[0], m[1]), std::max(m[2], m[3]));
  return FactorInPlace(scale);
}

LinearSolverStatus BandedLdlt::FactorInPlace(double scale) {
  const int n = n_;
  const int b = bandwidth_;
  double* data = band_.data();
  double bad_pivot = 0.0;
  const int bad_row = ForBandwidth<FactorKernel>(
      b, data, n, b, internal::kSingularPivotTolerance * scale, &bad_pivot);
  if (bad_row >= 0) {
    // Later rows would divide by this pivot: stopped there. The inertia is not defined.
    negative_pivots_ = 0;
    min_abs_pivot_ = std::abs(bad_pivot);
    message_ = internal::PivotFailureMessage("banded", bad_row, bad_pivot, scale);
    return LinearSolverStatus::kNumericalIssue;
  }
  const internal::PivotSummary pivots = internal::SummarizePivots(band_.row(b), n, scale);
  negative_pivots_ = pivots.negative;
  min_abs_pivot_ = pivots.min_abs;
  factorized_ = true;
  message_.clear();
  return LinearSolverStatus::kSuccess;
}

LinearSolverStatus BandedLdlt::Solve(const Vec& b_in, Vec* x) const {
  if (!factorized_ || x == nullptr || b_in.size() != n_ || x == &b_in) {
    return LinearSolverStatus::kInvalidInput;
  }
  *x = b_in;  // no allocation when x already has size n
  ForBandwidth<SolveKernel>(bandwidth_, band_.data(), n_, bandwidth_, x->data(), 1, std::ptrdiff_t{n_});
  return LinearSolverStatus::kSuccess;
}

LinearSolverStatus BandedLdlt::SolveMany(const Mat& b_in, Mat* x) const {
  if (!factorized_ || x == nullptr || x == &b_in || b_in.rows() != n_) {
    return LinearSolverStatus::kInvalidInput;
  }
  *x = b_in;  // no allocation when x already has B's size
  // Column by column, each forward sweep from its first non-zero: E_xu's three columns
  // at thread3d n = 1000 took 0.83 M instructions interleaved, 0.49 M this way
  // (callgrind); the factor (27 k doubles there) stays in cache between the passes. The
  // same operations per column either way, so the same bits.
  for (int c = 0; c < x->cols(); ++c) {
    ForBandwidth<SolveKernel>(bandwidth_, band_.data(), n_, bandwidth_, x->data() + c * std::ptrdiff_t{n_}, 1,
                              std::ptrdiff_t{n_});
  }
  return LinearSolverStatus::kSuccess;
}

}  // namespace snapthread
