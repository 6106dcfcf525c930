// SymmetricLinearSolver::InverseQuadraticForm (the implicit differentiation's
// E_ux E_xx^-1 E_xu, (2.14-2.15)) against a dense reference for every backend: random
// indefinite band matrices with right-hand sides that start at different rows (the
// banded backend sweeps forward from each column's first non-zero and skips the
// backward sweep), a thread3d Hessian at an equilibrium with its own E_xu, exact
// symmetry, no allocation once sized, and the invalid calls.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "linalg/linear_solver.h"
#include "models/models.h"
#include "solvers/solver.h"
#include "tracking/tracker.h"

namespace snapthread {
namespace {

using test_support::MallocsDuring;

constexpr double kEps = std::numeric_limits<double>::epsilon();

SparseMatrix DenseBandToSparse(const Mat& dense, int b) {
  const int n = static_cast<int>(dense.rows());
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < n; ++j)
    for (int i = std::max(0, j - b); i <= std::min(n - 1, j + b); ++i) t.emplace_back(i, j, dense(i, j));
  SparseMatrix a(n, n);
  a.setFromTriplets(t.begin(), t.end());
  a.makeCompressed();
  return a;
}

// Symmetric band, diagonally dominant, then shifted so a few eigenvalues are negative:
// indefinite but with every leading minor far from zero (no pivoting needed).
Mat IndefiniteBand(int n, int b, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mat m = Mat::Zero(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = j + 1; i <= std::min(n - 1, j + b); ++i) m(i, j) = m(j, i) = u(*rng);
  for (int i = 0; i < n; ++i) m(i, i) = (i % 7 == 3 ? -1.0 : 1.0) * (1.0 + m.row(i).cwiseAbs().sum());
  return m;
}

// The bound of a backward-stable solve: each column of A^-1 B has relative error
// <= c n eps kappa(A); B^T A^-1 B then errs by that times |B_i| |A^-1 B_j| (c = 10).
double Kappa(const Mat& a) {
  const Vec ev = Eigen::SelfAdjointEigenSolver<Mat>(a).eigenvalues().cwiseAbs();
  return ev.maxCoeff() / ev.minCoeff();
}
double Tolerance(const Mat& a, double kappa, const Mat& b, const Mat& a_inv_b, int i, int j) {
  return 10.0 * a.rows() * kEps * kappa * b.col(i).norm() * a_inv_b.col(j).norm();
}

class InverseQuadraticFormTest : public ::testing::TestWithParam<std::string> {
 protected:
  std::unique_ptr<SymmetricLinearSolver> Make(int n, int b) const {
    std::string error;
    auto s = MakeLinearSolver(GetParam(), n, b, &error);
    EXPECT_NE(s, nullptr) << error;
    return s;
  }
};

TEST_P(InverseQuadraticFormTest, EqualsTheDenseFormulaForRightHandSidesStartingAnywhere) {
  std::mt19937 rng(17);
  for (int n : {1, 5, 9, 40, 300}) {
    const int b = std::min(8, n - 1);
    const Mat a = IndefiniteBand(n, b, &rng);
    const SparseMatrix s = DenseBandToSparse(a, b);
    auto solver = Make(n, b);
    ASSERT_EQ(solver->Analyze(s), LinearSolverStatus::kSuccess);
    ASSERT_EQ(solver->Factorize(s), LinearSolverStatus::kSuccess) << solver->message();
    // Columns: dense; zero but for the last min(6, n) rows (E_xu's shape); starting in
    // the middle; all zero.
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Mat rhs = Mat::Zero(n, 4);
    for (int i = 0; i < n; ++i) rhs(i, 0) = u(rng);
    for (int i = std::max(0, n - 6); i < n; ++i) rhs(i, 1) = u(rng);
    for (int i = n / 2; i < n; ++i) rhs(i, 2) = u(rng);
    const Mat a_inv_b = a.ldlt().solve(rhs);
    const Mat reference = rhs.transpose() * a_inv_b;
    const double kappa = Kappa(a);
    Mat q;
    ASSERT_EQ(solver->InverseQuadraticForm(rhs, &q), LinearSolverStatus::kSuccess);
    ASSERT_EQ(q.rows(), 4);
    ASSERT_EQ(q.cols(), 4);
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(q(i, j), q(j, i)) << "n = " << n << ": not exactly symmetric";
        EXPECT_NEAR(q(i, j), reference(i, j), Tolerance(a, kappa, rhs, a_inv_b, i, j))
            << GetParam() << ", n = " << n << ", entry (" << i << ", " << j << ")";
      }
    }
    EXPECT_EQ(q(3, 3), 0.0);
    // Repeated calls (the scratch already sized) give the same bits and do not allocate.
    const Mat first = q;
    LinearSolverStatus again = LinearSolverStatus::kInvalidInput;
    EXPECT_EQ(MallocsDuring([&] { again = solver->InverseQuadraticForm(rhs, &q); }), 0) << "n = " << n;
    EXPECT_EQ(again, LinearSolverStatus::kSuccess);
    EXPECT_TRUE(q == first) << "n = " << n;
  }
}

// E_ux E_xx^-1 E_xu of a thread3d chain at an equilibrium: the matrices the tracker's K
// is made of (K = E_ux E_xx^-1 E_xu - E_uu).
TEST_P(InverseQuadraticFormTest, Thread3dImplicitDifferentiationTerm) {
  ModelParams p;
  p.model = "thread3d";
  p.Set("n", 30);
  Vec u = Vec::Zero(3);
  u << 0.8 * 30, 0.5, 0.2;
  EquilibriumTracker tracker(MakeModel(p), SolverOptions{});
  ASSERT_TRUE(tracker.Reset(u).summary.IsConverged());
  const Model* model = &tracker.model();
  const Vec x = tracker.state();
  SparseMatrix h = model->HessianPattern();
  model->Hessian(x, u, &h);
  Vec eu;
  Mat exu, euu;
  model->ControlDerivatives(x, u, &eu, &exu, &euu);
  auto solver = Make(model->NumStates(), model->HessianBandwidth());
  ASSERT_EQ(solver->Analyze(h), LinearSolverStatus::kSuccess);
  ASSERT_EQ(solver->Factorize(h), LinearSolverStatus::kSuccess) << solver->message();
  Mat q;
  ASSERT_EQ(solver->InverseQuadraticForm(exu, &q), LinearSolverStatus::kSuccess);
  const Mat dense = Mat(h);
  const Mat a_inv_b = dense.ldlt().solve(exu);
  const Mat reference = exu.transpose() * a_inv_b;
  const double kappa = Kappa(dense);
  for (int j = 0; j < q.cols(); ++j)
    for (int i = 0; i < q.rows(); ++i)
      EXPECT_NEAR(q(i, j), reference(i, j), Tolerance(dense, kappa, exu, a_inv_b, i, j)) << "(" << i << ", " << j << ")";
}

TEST_P(InverseQuadraticFormTest, InvalidCallsAreInvalidInput) {
  std::mt19937 rng(5);
  const Mat a = IndefiniteBand(12, 3, &rng);
  const SparseMatrix s = DenseBandToSparse(a, 3);
  auto solver = Make(12, 3);
  Mat rhs = Mat::Ones(12, 2), q;
  ASSERT_EQ(solver->Analyze(s), LinearSolverStatus::kSuccess);
  EXPECT_NE(solver->InverseQuadraticForm(rhs, &q), LinearSolverStatus::kSuccess);  // not factorised
  ASSERT_EQ(solver->Factorize(s), LinearSolverStatus::kSuccess);
  EXPECT_EQ(solver->InverseQuadraticForm(rhs, nullptr), LinearSolverStatus::kInvalidInput);
  EXPECT_EQ(solver->InverseQuadraticForm(rhs, &rhs), LinearSolverStatus::kInvalidInput);
  const Mat wrong_rows = Mat::Ones(11, 2);
  EXPECT_NE(solver->InverseQuadraticForm(wrong_rows, &q), LinearSolverStatus::kSuccess);
}

INSTANTIATE_TEST_SUITE_P(Backends, InverseQuadraticFormTest, ::testing::Values("cholmod", "dense", "banded"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace snapthread
