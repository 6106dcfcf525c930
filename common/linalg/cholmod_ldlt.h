// SuiteSparse CHOLMOD simplicial LDL^T with an AMD fill-reducing ordering, after Ceres'
// SuiteSparseCholesky (internal/ceres/suitesparse.cc): the backend owns its
// cholmod_common, Analyze() runs the symbolic analysis once per pattern, Factorize()
// only the numeric factorisation, Solve() uses cholmod_solve2 with persistent
// workspaces, and CHOLMOD status codes become text in message().
//
// No allocation after the first Factorize()/Solve() for a pattern. cholmod_factorize
// of a matrix with a non-natural ordering would allocate a permuted copy
// (cholmod_ptranspose) on every call, so this backend does the permutation itself:
// Analyze() takes the AMD permutation P from a first cholmod_analyze, builds the
// pattern of S = triu(P A P^T) once with a scatter map from A's lower triangle, and
// analyses S with the natural ordering. Factorize() scatters A's values into S (O(nnz))
// and factorises S in place; Solve() permutes b and x in preallocated vectors.
//
// Not thread-safe: Solve() is const but reuses the mutable CHOLMOD workspaces.
#pragma once

#include <string_view>
#include <vector>

#include <suitesparse/cholmod.h>

#include "linalg/ldlt_support.h"
#include "linalg/linear_solver.h"

namespace snapthread {

class CholmodLdlt final : public SymmetricLinearSolver {
 public:
  CholmodLdlt();
  ~CholmodLdlt() override;
  CholmodLdlt(const CholmodLdlt&) = delete;
  CholmodLdlt& operator=(const CholmodLdlt&) = delete;

  std::string_view Name() const override { return "cholmod"; }
  LinearSolverStatus Analyze(const SparseMatrix& a) override;
  LinearSolverStatus Factorize(const SparseMatrix& a) override;
  LinearSolverStatus Solve(const Vec& b, Vec* x) const override;

 private:
  void FreeFactor();
  // Appends CHOLMOD's status (cc_.status) as text to message_.
  void AppendCholmodStatus();
  cholmod_sparse ViewOfS();
  // Analyze()'s steps, in order: the AMD permutation perm_ (false: CHOLMOD failed, with
  // message_); S's pattern and the scatter map from A; the symbolic analysis of S in its
  // natural order (false: failed, message_ set, the pattern cleared); the warm-up that
  // allocates the numeric storage and the solve workspaces now.
  bool OrderAmd(const SparseMatrix& a);
  void BuildPermutedPattern(const SparseMatrix& a);
  bool AnalyzeNaturalOrder();
  void WarmUp();

  mutable cholmod_common cc_;
  cholmod_factor* factor_ = nullptr;  // of S, natural ordering
  internal::PatternCopy pattern_;
  int n_ = 0;
  std::vector<int> perm_;     // S(k, l) = A(perm_[k], perm_[l])
  std::vector<int> s_outer_;  // S = triu(P A P^T), compressed column, sorted rows
  std::vector<int> s_inner_;
  std::vector<double> s_values_;
  // For the p-th stored entry of A (in PatternCopy order), its slot in s_values_, or -1
  // for strictly upper entries (not read: A is symmetric, the lower triangle is used).
  std::vector<int> scatter_;
  mutable Vec permuted_rhs_;
  mutable cholmod_dense* x_ = nullptr;  // cholmod_solve2 workspaces, kept between calls
  mutable cholmod_dense* y_ = nullptr;
  mutable cholmod_dense* e_ = nullptr;
  bool factorized_ = false;
};

}  // namespace snapthread
