// Sparse symmetric (possibly indefinite) LDL^T factorisation behind one interface,
// after Ceres' SparseCholesky and libigl's precompute/solve split: Analyze() once per
// sparsity pattern, then Factorize() (numeric only) and Solve() each step.
//
// Numeric code reports status (Eigen style), it never throws.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "numeric/types.h"

namespace snapthread {

enum class LinearSolverStatus {
  kSuccess,
  kNumericalIssue,  // zero / non-finite pivot: the matrix is singular to working precision
  kInvalidInput,    // wrong size, pattern differs from the analysed one, not analysed
};
const char* ToString(LinearSolverStatus s);

class SymmetricLinearSolver {
 public:
  virtual ~SymmetricLinearSolver() = default;
  virtual std::string_view Name() const = 0;

  // Symbolic analysis of a full symmetric pattern (both triangles stored; a pattern that
  // is not structurally symmetric is kInvalidInput). Allocates.
  virtual LinearSolverStatus Analyze(const SparseMatrix& a) = 0;
  // Numeric LDL^T of a matrix with the analysed pattern. Every backend reads only the
  // values of the lower triangle. Does not allocate after the first call for a pattern
  // (backends that cannot promise this say so in Name()).
  virtual LinearSolverStatus Factorize(const SparseMatrix& a) = 0;
  // x = A^-1 b with the last successful factorisation. x may alias nothing.
  virtual LinearSolverStatus Solve(const Vec& b, Vec* x) const = 0;
  // X = A^-1 B for every column of B in one call: the implicit differentiation's
  // right-hand sides (E_xu, one column per control) share one pass over the factor in
  // the banded backend. Column j equals Solve(B.col(j)) to the last bit. x may alias
  // nothing; no allocation once *x has B's size (this default version copies each column
  // through two scratch vectors, sized on the first call).
  virtual LinearSolverStatus SolveMany(const Mat& b, Mat* x) const;
  // B^T A^-1 B (cols x cols) with the last factorisation: the implicit differentiation's
  // E_ux E_xx^-1 E_xu (2.14-2.15) without the full solves. With A = L D L^T it is
  // (L^-1 B)^T D^-1 (L^-1 B): the banded backend runs the forward sweeps only, each from
  // its column's first non-zero, so a B that is non-zero on the last rows only (E_xu:
  // the nodes next to the grasp) costs O(b) per column instead of O(n b). Exactly
  // symmetric. out may alias nothing; no allocation once *out is cols x cols (this
  // default version, SolveMany() and a product, sizes its scratch on the first call).
  virtual LinearSolverStatus InverseQuadraticForm(const Mat& b, Mat* out) const;

  // Direct assembly (libigl's precompute / solve split taken one step further): a
  // backend that factorises in band storage hands out that storage, a model writes the
  // lower band of the matrix there (the layout of banded_ldlt.h; slots of the analysed
  // pattern only), and FactorizeAssembled() factorises it in place — the same factor
  // as Factorize() of the compressed matrix with those values, without the copy. Writing
  // into it discards the last factorisation. nullptr (the default): no such storage.
  virtual double* AssemblyBand(int* /*bandwidth*/) { return nullptr; }
  virtual LinearSolverStatus FactorizeAssembled() {
    message_ = std::string(Name()) + ": no direct assembly";
    return LinearSolverStatus::kInvalidInput;
  }

  // Inertia from the pivots of D in A = L D L^T (Sylvester's law of inertia): the
  // number of negative eigenvalues of A (valid after a successful Factorize()).
  // Every backend records both from its pivots in Factorize().
  int NegativePivots() const { return negative_pivots_; }
  // Smallest |d_ii|: a cheap singularity indicator.
  double MinAbsPivot() const { return min_abs_pivot_; }

  // Text of the last failure ("" after success).
  const std::string& message() const { return message_; }

 protected:
  std::string message_;
  int negative_pivots_ = 0;
  // SolveMany()'s scratch columns and InverseQuadraticForm()'s A^-1 B (default versions).
  mutable Vec many_rhs_, many_x_;
  mutable Mat quad_x_;
  double min_abs_pivot_ = 0.0;
};

// Backends: "cholmod" (SuiteSparse simplicial LDL^T, AMD ordering), "dense" (Eigen,
// for small n), "banded" (band LDL^T without pivoting, for chains), "auto" (picks by n
// and bandwidth; see MakeLinearSolver in linear_solver.cc for the measured rule).
// Returns nullptr and sets *error for an unknown name.
std::unique_ptr<SymmetricLinearSolver> MakeLinearSolver(std::string_view name, int n,
                                                        int bandwidth, std::string* error);
std::vector<std::string> LinearSolverNames();

}  // namespace snapthread
