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
// both contiguous in the band. The u(i,.) are a forward substitution with the rows
// above, taken column by column: once u(i,k) is final it is subtracted from every later
// u(i,j) at once, so the chain from one u to the next is one multiply-subtract (as a dot
// product per j, the chain was the whole sum plus the subtraction: thread3d n = 1000
// factorised in ~60 cycles a row, latency-bound).
// 1/d_j is kept beside the band (dinv): a row divides once, for its own pivot, and
// L(i,j) = u(i,j) * (1/d_j) is a multiplication (the b divisions a row would otherwise
// issue are the factorisation's slowest instructions; the solves' D step multiplies too).
//
// Each kernel comes twice: for any bandwidth (rows near the top, where the band is cut
// off, and bandwidths without a specialisation) and for a bandwidth B fixed at compile
// time on rows with a full band, where the loops unroll completely (a factorisation of a
// thread3d Hessian, B = 8, takes 2.7x fewer instructions, measured with callgrind). Both
// do the same operations in the same order, so the factor and the solutions are the same
// to the last bit whichever runs.

// *m = max(*m, |a|), NaN ignored (*m never becomes NaN), as std::max(*m, |a|). Three
// running maxima (the order of a max does not change it) keep the chain per row short.
inline void MaxAbs(double a, double* m) {
  const double x = std::abs(a);
  *m = x > *m ? x : *m;
}

// Row i of the factorisation, band cut off at column k0 = max(0, i - b). Returns d_i.
inline double FactorRow(double* data, double* dinv, int i, int b, double* acc) {
  const int ld = b + 1;
  double* ri = data + static_cast<std::ptrdiff_t>(i) * ld;  // ri[k - i + b] = L(i,k)
  const int k0 = std::max(0, i - b);
  for (int k = k0; k <= i; ++k) MaxAbs(ri[k - i + b], &acc[0]);
  for (int k = k0; k < i; ++k) {  // u(i,k) is final: subtract it from the later ones
    const double uk = ri[k - i + b];
    for (int j = k + 1; j < i; ++j) ri[j - i + b] -= uk * data[static_cast<std::ptrdiff_t>(j) * ld + k - j + b];
  }
  double di = ri[b];
  for (int j = k0; j < i; ++j) {
    const double u = ri[j - i + b];
    const double l = u * dinv[j];
    di -= u * l;
    ri[j - i + b] = l;
  }
  ri[b] = di;
  dinv[i] = 1.0 / di;
  return di;
}

// Row i >= B with the full band of a compile-time B: FactorRow() unrolled, u(i,.) in
// registers.
template <int B>
inline double FactorFullRow(double* data, double* dinv, int i, double* acc) {
  constexpr int ld = B + 1;
  double* ri = data + static_cast<std::ptrdiff_t>(i) * ld;
  const double* r0 = ri - B * ld;  // row i - B; L(i-B+j, i-B+k) = r0[j ld + B - j + k]
  const double* q0 = dinv + (i - B);
  double u[B > 0 ? B : 1];
#pragma GCC unroll 32
  for (int j = 0; j <= B; ++j) MaxAbs(ri[j], &acc[j % 3]);
#pragma GCC unroll 32
  for (int j = 0; j < B; ++j) u[j] = ri[j];
#pragma GCC unroll 32
  for (int k = 0; k < B; ++k) {
#pragma GCC unroll 32
    for (int j = k + 1; j < B; ++j) u[j] -= u[k] * r0[j * ld + B - j + k];
  }
  double di = ri[B];
#pragma GCC unroll 32
  for (int j = 0; j < B; ++j) {
    const double l = u[j] * q0[j];
    di -= u[j] * l;
    ri[j] = l;
  }
  ri[B] = di;
  dinv[i] = 1.0 / di;
  return di;
}

// Factorises rows 0..n-1 in place and returns max |a_ij| over the lower band as it was
// (each row's entries are read once, on the way in: no separate pass for the scale of
// the singularity test). The pivots are tested afterwards (SummarizePivots): rows
// before the first bad pivot do not depend on the rows after it, so the first bad row
// and its pivot are those a factorisation stopping there would report, and a zero pivot
// only fills the rows after it with inf / NaN. B = 0: no specialisation.
template <int B>
double FactorBand(double* data, double* dinv, int n, int b) {
  double acc[3] = {0.0, 0.0, 0.0};
  for (int i = 0; i < n; ++i) {
    if (B > 0 && i >= B) {
      FactorFullRow<B>(data, dinv, i, acc);
    } else {
      FactorRow(data, dinv, i, b, acc);
    }
  }
  return std::max(std::max(acc[0], acc[1]), acc[2]);
}

// Index of v's first non-zero entry (n if none), eight entries per test: the
// right-hand sides that matter here (E_xu's columns, the predictor's E_xu du) are zero
// for all but their last few rows.
inline int FirstNonZero(const double* v, int n) {
  int k = 0;
  for (; k + 8 <= n; k += 8) {
    int any = 0;
#pragma GCC unroll 8
    for (int q = 0; q < 8; ++q) any |= static_cast<int>(v[k + q] != 0.0);
    if (any != 0) break;
  }
  while (k < n && v[k] == 0.0) ++k;
  return k;
}

// L y = v in place from row `first` (rows above it are zero in v and stay zero: each of
// their dot products is a sum of zeros). Row i of L is contiguous.
template <int B>
void ForwardBand(const double* data, int n, int b, double* v, int first) {
  const int ld = b + 1;
  // Rows 0 .. head-1 have a band cut off by the matrix' edge (every row without a
  // compile-time B); rows head .. n-1 have the full band of B.
  const int head = B > 0 ? std::min(B, n) : n;
  for (int i = first; i < head; ++i) {
    const double* ri = data + static_cast<std::ptrdiff_t>(i) * ld;
    double s = 0.0;
    for (int k = std::max(0, i - b); k < i; ++k) s += ri[k - i + b] * v[k];
    v[i] -= s;
  }
  if constexpr (B > 0) {
    for (int i = std::max(head, first); i < n; ++i) {
      const double* ri = data + static_cast<std::ptrdiff_t>(i) * (B + 1);
      double* xi = v + (i - B);  // xi[B] is row i
      double s = 0.0;
#pragma GCC unroll 32
      for (int k = 0; k < B; ++k) s += ri[k] * xi[k];
      xi[B] -= s;
    }
  }
}

// x = A^-1 v in place: L y = v forward, D z = y (z_i = y_i / d_i, rows from `first`:
// above it y is zero), L^T x = z backward (column-oriented: row i of L is column i of
// L^T).
template <int B>
void SolveBand(const double* data, const double* dinv, int n, int b, double* v) {
  const int ld = b + 1;
  const int head = B > 0 ? std::min(B, n) : n;
  // E_xu's columns are zero but for the few nodes next to the grasp, the chain's last:
  // the forward sweep and the D step start at the first non-zero.
  const int first = FirstNonZero(v, n);
  ForwardBand<B>(data, n, b, v, first);
  for (int i = first; i < n; ++i) v[i] *= dinv[i];
  if constexpr (B > 0) {
    for (int i = n - 1; i >= head; --i) {
      const double* ri = data + static_cast<std::ptrdiff_t>(i) * (B + 1);
      double* xc = v + (i - B);
      const double xi = xc[B];
#pragma GCC unroll 32
      for (int k = 0; k < B; ++k) xc[k] -= ri[k] * xi;
    }
  }
  for (int i = std::min(head, n) - 1; i > 0; --i) {
    const double* ri = data + static_cast<std::ptrdiff_t>(i) * ld;
    const double xi = v[i];
    for (int k = std::max(0, i - b); k < i; ++k) v[k] -= ri[k - i + b] * xi;
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
  static double Run(double* data, double* dinv, int n, int b) { return FactorBand<B>(data, dinv, n, b); }
};
template <int B>
struct SolveKernel {
  static int Run(const double* data, const double* dinv, int n, int b, double* v) {
    SolveBand<B>(data, dinv, n, b, v);
    return 0;
  }
};
template <int B>
struct ForwardKernel {
  static int Run(const double* data, int n, int b, double* v, int first) {
    ForwardBand<B>(data, n, b, v, first);
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
  dinv_.setZero(n_);
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
  if (a.isCompressed()) {
    const double* values = a.valuePtr();
    for (const Scatter& e : scatter_) data[e.slot] = values[e.value];
  } else {
    for (int j = 0; j < n; ++j) {
      const int begin = internal::ColumnBegin(a, j);
      const int* rows = a.innerIndexPtr() + begin;
      const double* values = a.valuePtr() + begin;
      for (int p = 0, count = internal::ColumnCount(a, j); p < count; ++p) {
        if (rows[p] < j) continue;
        band_(j - rows[p] + b, rows[p]) = values[p];
      }
    }
  }
  return FactorInPlace();
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
  return FactorInPlace();
}

LinearSolverStatus BandedLdlt::FactorInPlace() {
  const int n = n_;
  const int b = bandwidth_;
  // scale = max |a_ij| over the pattern's lower triangle (the holes are 0, the slots
  // outside the matrix in the first b rows are not read), from the factorisation's pass.
  const double scale = ForBandwidth<FactorKernel>(b, band_.data(), dinv_.data(), n, b);
  const internal::PivotSummary pivots = internal::SummarizePivots(band_.row(b), n, scale);
  if (pivots.first_bad >= 0) {
    // The rows after it divided by this pivot. The inertia is not defined.
    const double bad_pivot = band_(b, pivots.first_bad);
    negative_pivots_ = 0;
    min_abs_pivot_ = std::abs(bad_pivot);
    message_ = internal::PivotFailureMessage("banded", pivots.first_bad, bad_pivot, scale);
    return LinearSolverStatus::kNumericalIssue;
  }
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
  ForBandwidth<SolveKernel>(bandwidth_, band_.data(), dinv_.data(), n_, bandwidth_, x->data());
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
  // same operations per column as Solve(), so the same bits.
  for (int c = 0; c < x->cols(); ++c) {
    ForBandwidth<SolveKernel>(bandwidth_, band_.data(), dinv_.data(), n_, bandwidth_,
                              x->data() + c * std::ptrdiff_t{n_});
  }
  return LinearSolverStatus::kSuccess;
}

LinearSolverStatus BandedLdlt::InverseQuadraticForm(const Mat& b_in, Mat* out) const {
  if (!factorized_ || out == nullptr || out == &b_in || b_in.rows() != n_) {
    return LinearSolverStatus::kInvalidInput;
  }
  const int m = static_cast<int>(b_in.cols());
  if (out->rows() != m || out->cols() != m) out->resize(m, m);
  // quad_y_ is zero between calls (sized once): each column copies and sweeps only its
  // rows from its first non-zero on, and clears them again at the end.
  if (quad_y_.rows() != n_ || quad_y_.cols() != m) quad_y_.setZero(n_, m);
  first_.resize(m);
  // B^T A^-1 B = (L^-1 B)^T D^-1 (L^-1 B): the forward sweeps alone, each from its
  // column's first non-zero. E_xu is non-zero only on the last nodes, so this is
  // O(b) per column where a solve is O(n b).
  for (int c = 0; c < m; ++c) {
    const double* bc = b_in.data() + c * std::ptrdiff_t{n_};
    double* y = quad_y_.data() + c * std::ptrdiff_t{n_};
    const int first = FirstNonZero(bc, n_);
    first_[c] = first;
    std::copy(bc + first, bc + n_, y + first);
    ForBandwidth<ForwardKernel>(bandwidth_, band_.data(), n_, bandwidth_, y, first);
  }
  const double* dinv = dinv_.data();
  for (int j = 0; j < m; ++j) {
    const double* yj = quad_y_.data() + j * std::ptrdiff_t{n_};
    for (int i = 0; i <= j; ++i) {
      const double* yi = quad_y_.data() + i * std::ptrdiff_t{n_};
      double s = 0.0;
      for (int k = std::max(first_[i], first_[j]); k < n_; ++k) s += yi[k] * (yj[k] * dinv[k]);
      (*out)(i, j) = s;
      (*out)(j, i) = s;
    }
  }
  for (int c = 0; c < m; ++c) {
    double* y = quad_y_.data() + c * std::ptrdiff_t{n_};
    std::fill(y + first_[c], y + n_, 0.0);
  }
  return LinearSolverStatus::kSuccess;
}

}  // namespace snapthread
