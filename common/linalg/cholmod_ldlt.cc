#include "linalg/cholmod_ldlt.h"

#include <algorithm>
#include <array>
#include <string>

namespace snapthread {
namespace {

// A cholmod_sparse header over Eigen's arrays (no copy). CHOLMOD reads only the triangle
// selected by stype (> 0 upper, < 0 lower) and ignores the other one (cholmod_core.h,
// "Entries in the lower triangular part are ignored"), so a full symmetric matrix can be
// passed as is. Uncompressed Eigen storage maps to CHOLMOD's unpacked form (nz per column).
cholmod_sparse ViewOf(const SparseMatrix& a, int stype) {
  cholmod_sparse m{};
  m.nrow = static_cast<size_t>(a.rows());
  m.ncol = static_cast<size_t>(a.cols());
  m.nzmax = static_cast<size_t>(a.outerIndexPtr()[a.cols()]);
  m.p = const_cast<int*>(a.outerIndexPtr());
  m.i = const_cast<int*>(a.innerIndexPtr());
  m.nz = a.isCompressed() ? nullptr : const_cast<int*>(a.innerNonZeroPtr());
  m.x = const_cast<double*>(a.valuePtr());
  m.z = nullptr;
  m.stype = stype;
  m.itype = CHOLMOD_INT;
  m.xtype = CHOLMOD_REAL;
  m.dtype = CHOLMOD_DOUBLE;
  m.sorted = 1;
  m.packed = a.isCompressed() ? 1 : 0;
  return m;
}

const char* CholmodStatusText(int status) {
  switch (status) {
    case CHOLMOD_OK: return "CHOLMOD_OK";
    case CHOLMOD_NOT_INSTALLED: return "CHOLMOD_NOT_INSTALLED: method not installed";
    case CHOLMOD_OUT_OF_MEMORY: return "CHOLMOD_OUT_OF_MEMORY: out of memory";
    case CHOLMOD_TOO_LARGE: return "CHOLMOD_TOO_LARGE: integer overflow";
    case CHOLMOD_INVALID: return "CHOLMOD_INVALID: invalid input";
    case CHOLMOD_GPU_PROBLEM: return "CHOLMOD_GPU_PROBLEM: GPU error";
    case CHOLMOD_NOT_POSDEF: return "CHOLMOD_NOT_POSDEF: zero pivot in LDL^T";
    case CHOLMOD_DSMALL: return "CHOLMOD_DSMALL: a pivot is below Common->dbound";
    default: return "unknown CHOLMOD status";
  }
}

}  // namespace

CholmodLdlt::CholmodLdlt() {
  cholmod_start(&cc_);
  // Errors and warnings go to message(), not to stdout.
  cc_.print = 0;
  // Simplicial LDL^T (not LL^T): D carries the inertia of an indefinite Hessian.
  cc_.supernodal = CHOLMOD_SIMPLICIAL;
  cc_.final_ll = 0;
  cc_.final_asis = 1;
}

CholmodLdlt::~CholmodLdlt() {
  FreeFactor();
  cholmod_finish(&cc_);
}

void CholmodLdlt::FreeFactor() {
  if (factor_ != nullptr) cholmod_free_factor(&factor_, &cc_);
  if (x_ != nullptr) cholmod_free_dense(&x_, &cc_);
  if (y_ != nullptr) cholmod_free_dense(&y_, &cc_);
  if (e_ != nullptr) cholmod_free_dense(&e_, &cc_);
}

void CholmodLdlt::AppendCholmodStatus() {
  message_ += " (";
  message_ += CholmodStatusText(cc_.status);
  message_ += ")";
}

cholmod_sparse CholmodLdlt::ViewOfS() {
  cholmod_sparse s{};
  s.nrow = s.ncol = static_cast<size_t>(n_);
  s.nzmax = s_inner_.size();
  s.p = s_outer_.data();
  s.i = s_inner_.data();
  s.x = s_values_.data();
  s.stype = 1;  // S holds triu(P A P^T) only
  s.itype = CHOLMOD_INT;
  s.xtype = CHOLMOD_REAL;
  s.dtype = CHOLMOD_DOUBLE;
  s.sorted = 1;
  s.packed = 1;
  return s;
}

bool CholmodLdlt::OrderAmd(const SparseMatrix& a) {
  const int n = n_;
  // 1. AMD ordering of A's lower triangle (what cholmod_analyze would use).
  cholmod_sparse view = ViewOf(a, -1);
  cc_.nmethods = 1;
  cc_.method[0].ordering = CHOLMOD_AMD;
  cc_.postorder = 1;
  cc_.status = CHOLMOD_OK;
  cholmod_factor* ordering = cholmod_analyze(&view, &cc_);
  if (ordering == nullptr || cc_.status < CHOLMOD_OK) {
    message_ = "cholmod: cholmod_analyze (AMD) failed";
    AppendCholmodStatus();
    if (ordering != nullptr) cholmod_free_factor(&ordering, &cc_);
    return false;
  }
  const int* p = static_cast<const int*>(ordering->Perm);
  perm_.assign(p, p + n);
  cholmod_free_factor(&ordering, &cc_);
  return true;
}

void CholmodLdlt::BuildPermutedPattern(const SparseMatrix& a) {
  const int n = n_;
  // inverse[i]: where row i of A goes under P.
  std::vector<int> inverse(n);
  for (int k = 0; k < n; ++k) inverse[perm_[k]] = k;
  // 2. Pattern of S = triu(P A P^T) and the scatter map from A's lower triangle: entry
  //    A(i,j), i >= j, lands at S(min(pi, pj), max(pi, pj)) with pi = inverse[i].
  pattern_.Assign(a);
  const std::vector<int>& outer = pattern_.outer();
  const std::vector<int>& inner = pattern_.inner();
  struct Slot {
    int col, row, source;
  };
  std::vector<Slot> slots;
  slots.reserve(static_cast<size_t>(pattern_.nonzeros() / 2 + n));
  for (int j = 0; j < n; ++j) {
    for (int q = outer[j]; q < outer[j + 1]; ++q) {
      const int i = inner[q];
      if (i < j) continue;
      const int pi = inverse[i], pj = inverse[j];
      slots.push_back({std::max(pi, pj), std::min(pi, pj), q});
    }
  }
  std::sort(slots.begin(), slots.end(), [](const Slot& x, const Slot& y) {
    return x.col != y.col ? x.col < y.col : x.row < y.row;
  });
  s_outer_.assign(n + 1, 0);
  s_inner_.resize(slots.size());
  s_values_.assign(slots.size(), 0.0);
  scatter_.assign(static_cast<size_t>(pattern_.nonzeros()), -1);
  for (size_t k = 0; k < slots.size(); ++k) {
    ++s_outer_[slots[k].col + 1];
    s_inner_[k] = slots[k].row;
    scatter_[slots[k].source] = static_cast<int>(k);
  }
  for (int j = 0; j < n; ++j) s_outer_[j + 1] += s_outer_[j];
}

bool CholmodLdlt::AnalyzeNaturalOrder() {
  // 3. Symbolic analysis of S in its own (natural) order: cholmod_factorize then works
  //    on S directly instead of allocating a permuted copy per call.
  cc_.method[0].ordering = CHOLMOD_NATURAL;
  cc_.postorder = 0;
  cholmod_sparse s = ViewOfS();
  cc_.status = CHOLMOD_OK;
  factor_ = cholmod_analyze(&s, &cc_);
  if (factor_ == nullptr || cc_.status < CHOLMOD_OK) {
    message_ = "cholmod: cholmod_analyze (natural order of P A P^T) failed";
    AppendCholmodStatus();
    FreeFactor();
    pattern_.Clear();
    return false;
  }
  return true;
}

void CholmodLdlt::WarmUp() {
  const int n = n_;
  permuted_rhs_.setZero(n);
  // Warm-up: one numeric factorisation (the identity on S's pattern) and one solve
  // allocate the factor's numeric storage and cholmod_solve2's workspaces now, so that
  // a backend used only now and then (the solvers' second factorisation, of shifted or
  // restricted Hessians) does not allocate on its first use in the middle of a path.
  for (int j = 0; j < n; ++j) {
    for (int q = s_outer_[j]; q < s_outer_[j + 1]; ++q) s_values_[q] = s_inner_[q] == j ? 1.0 : 0.0;
  }
  cholmod_sparse s = ViewOfS();
  cc_.status = CHOLMOD_OK;
  if (cholmod_factorize(&s, factor_, &cc_) && cc_.status == CHOLMOD_OK) {
    factorized_ = true;
    const Vec zero = Vec::Zero(n);
    Vec x;
    Solve(zero, &x);
    factorized_ = false;
  }
}

LinearSolverStatus CholmodLdlt::Analyze(const SparseMatrix& a) {
  factorized_ = false;
  FreeFactor();
  pattern_.Clear();
  if (!internal::ValidateForAnalysis(a, &message_)) {
    message_ = "cholmod: " + message_;
    return LinearSolverStatus::kInvalidInput;
  }
  n_ = static_cast<int>(a.cols());
  if (!OrderAmd(a)) return LinearSolverStatus::kInvalidInput;
  BuildPermutedPattern(a);
  if (!AnalyzeNaturalOrder()) return LinearSolverStatus::kInvalidInput;
  WarmUp();
  std::fill(s_values_.begin(), s_values_.end(), 0.0);
  message_.clear();
  return LinearSolverStatus::kSuccess;
}

LinearSolverStatus CholmodLdlt::Factorize(const SparseMatrix& a) {
  factorized_ = false;
  if (pattern_.Empty() || factor_ == nullptr) {
    message_ = "cholmod: Factorize() before a successful Analyze()";
    return LinearSolverStatus::kInvalidInput;
  }
  if (!pattern_.Matches(a)) {
    message_ = "cholmod: the pattern differs from the analysed one";
    return LinearSolverStatus::kInvalidInput;
  }
  const std::vector<int>& outer = pattern_.outer();
  for (int j = 0; j < n_; ++j) {
    const double* values = a.valuePtr() + internal::ColumnBegin(a, j);
    const int* slot = scatter_.data() + outer[j];
    for (int q = 0, count = outer[j + 1] - outer[j]; q < count; ++q) {
      if (slot[q] >= 0) s_values_[slot[q]] = values[q];
    }
  }
  cholmod_sparse s = ViewOfS();
  cc_.status = CHOLMOD_OK;
  const int ok = cholmod_factorize(&s, factor_, &cc_);
  if (!ok || cc_.status < CHOLMOD_OK) {
    message_ = "cholmod: cholmod_factorize failed";
    AppendCholmodStatus();
    return LinearSolverStatus::kNumericalIssue;
  }
  if (factor_->is_ll || factor_->is_super) {
    message_ = "cholmod: expected a simplicial LDL^T factor";
    return LinearSolverStatus::kNumericalIssue;
  }
  // Simplicial LDL^T: column j of L starts with its diagonal, which holds d_j.
  const int* lp = static_cast<const int*>(factor_->p);
  const double* lx = static_cast<const double*>(factor_->x);
  const auto d = [lp, lx](int j) { return lx[lp[j]]; };
  const double scale = internal::MaxAbsEntry(a);
  const internal::PivotSummary pivots = internal::SummarizePivots(d, n_, scale);
  negative_pivots_ = pivots.negative;
  min_abs_pivot_ = pivots.min_abs;
  if (cc_.status == CHOLMOD_NOT_POSDEF || pivots.first_bad >= 0) {
    // CHOLMOD flags an exactly zero pivot (factor_->minor); the relative test catches
    // round-off zeros. Pivot indices are reported in the original numbering.
    const int k = pivots.first_bad >= 0 ? pivots.first_bad
                                        : static_cast<int>(std::min<size_t>(factor_->minor,
                                                                            n_ - 1));
    message_ = internal::PivotFailureMessage("cholmod", perm_[k], d(k), scale);
    if (cc_.status != CHOLMOD_OK) AppendCholmodStatus();
    return LinearSolverStatus::kNumericalIssue;
  }
  factorized_ = true;
  message_.clear();
  return LinearSolverStatus::kSuccess;
}

LinearSolverStatus CholmodLdlt::Solve(const Vec& b, Vec* x) const {
  if (!factorized_ || x == nullptr || x == &b || b.size() != n_) {
    return LinearSolverStatus::kInvalidInput;
  }
  // A = P^T S P: solve S y = P b, then x = P^T y.
  for (int k = 0; k < n_; ++k) permuted_rhs_[k] = b[perm_[k]];
  cholmod_dense rhs{};
  rhs.nrow = static_cast<size_t>(n_);
  rhs.ncol = 1;
  rhs.nzmax = static_cast<size_t>(n_);
  rhs.d = static_cast<size_t>(n_);
  rhs.x = permuted_rhs_.data();
  rhs.xtype = CHOLMOD_REAL;
  rhs.dtype = CHOLMOD_DOUBLE;
  // cholmod_solve2 keeps Y as a 4 x n workspace (4 right-hand sides per sweep) but its
  // ptrans() shrinks Y's header to 1 x n for our single column, so the next call's
  // ensure_dense() sees the "wrong" size and frees and reallocates Y every time
  // (CHOLMOD 3.x / SuiteSparse 5.x, cholmod_solve.c). Restoring the header of the
  // buffer it allocated keeps repeated solves allocation-free.
  constexpr size_t kSolveBlock = 4;
  if (y_ != nullptr && y_->xtype == CHOLMOD_REAL &&
      y_->nzmax >= kSolveBlock * static_cast<size_t>(n_)) {
    y_->nrow = kSolveBlock;
    y_->d = kSolveBlock;
    y_->ncol = static_cast<size_t>(n_);
  }
  cc_.status = CHOLMOD_OK;
  if (!cholmod_solve2(CHOLMOD_A, factor_, &rhs, nullptr, &x_, nullptr, &y_, &e_, &cc_) ||
      cc_.status < CHOLMOD_OK) {
    return LinearSolverStatus::kNumericalIssue;
  }
  x->resize(n_);
  const double* y = static_cast<const double*>(x_->x);
  for (int k = 0; k < n_; ++k) (*x)[perm_[k]] = y[k];
  return LinearSolverStatus::kSuccess;
}

}  // namespace snapthread
