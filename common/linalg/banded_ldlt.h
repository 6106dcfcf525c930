// Band LDL^T without pivoting, for chains (curve2d, thread3d: E_xx couples each node
// with its neighbours only, so its half-bandwidth b is a small constant).
//
// Storage is row-band: column i of a (b+1) x n column-major array holds
// [L(i,i-b) ... L(i,i-1), d_i] (and 1/d_i beside it), so the dot products of the
// factorisation and of both triangular solves run over contiguous memory. O(n b^2) factorisation, O(n b) solve,
// no allocation after Analyze() (Solve() allocates only if *x has the wrong size).
//
// Analyze() also records where each stored lower-triangle value of the pattern goes in
// the band (scatter_) and which band slots inside the matrix the pattern leaves empty
// (holes_, they take fill-in): Factorize() of a compressed matrix is then one pass over
// the values without per-column bookkeeping, and the band is never cleared as a whole.
// SolveMany() solves column by column, each forward sweep from the column's first non-zero.
//
// Without pivoting the factorisation exists iff every leading principal minor is
// non-zero; for a symmetric matrix this is enough for indefinite Hessians (the
// higher-order solver needs their inertia), and a zero / non-finite pivot is reported
// as kNumericalIssue.
#pragma once

#include <string_view>
#include <vector>

#include "linalg/ldlt_support.h"
#include "linalg/linear_solver.h"

namespace snapthread {

class BandedLdlt final : public SymmetricLinearSolver {
 public:
  std::string_view Name() const override { return "banded"; }
  LinearSolverStatus Analyze(const SparseMatrix& a) override;
  LinearSolverStatus Factorize(const SparseMatrix& a) override;
  LinearSolverStatus Solve(const Vec& b, Vec* x) const override;
  LinearSolverStatus SolveMany(const Mat& b, Mat* x) const override;
  // Forward sweeps only: (L^-1 B)^T D^-1 (L^-1 B), each column from its first non-zero.
  LinearSolverStatus InverseQuadraticForm(const Mat& b, Mat* out) const override;

  // The band itself (after Analyze()): the model writes A(i, j), i >= j, at
  // data[i (b + 1) + j - i + b]; FactorizeAssembled() clears the slots outside the
  // pattern (the last factor's fill-in) and factorises in place.
  double* AssemblyBand(int* bandwidth) override;
  LinearSolverStatus FactorizeAssembled() override;

  // Half-bandwidth max |i - j| of the analysed pattern (-1 before Analyze()).
  int HalfBandwidth() const { return bandwidth_; }

 private:
  internal::PatternCopy pattern_;
  int n_ = 0;
  int bandwidth_ = -1;
  Mat band_;  // (b+1) x n, see the file comment
  Vec dinv_;  // 1 / d_i of the factorisation (multiplications in the factor and the solves)
  mutable Mat quad_y_;              // InverseQuadraticForm's L^-1 B
  mutable std::vector<int> first_;  // ... and each column's first non-zero row
  // Each stored lower-triangle entry of a compressed matrix: its index in valuePtr()
  // and its slot in band_ (strictly upper entries are not read: A is symmetric).
  struct Scatter {
    int value;
    int slot;
  };
  std::vector<Scatter> scatter_;
  std::vector<int> holes_;  // band slots inside the matrix that the pattern leaves empty
  bool factorized_ = false;

  // The factorisation of band_ as it stands (holes cleared); the singularity test's
  // scale max |a_ij| is taken on the way.
  LinearSolverStatus FactorInPlace();
};

}  // namespace snapthread
