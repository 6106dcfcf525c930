// One test body per LDL^T backend (TEST_P, after Ceres' sparse_cholesky_test.cc),
// checked against a dense solve by relative norm, plus inertia (Sylvester's law), status
// codes and a malloc-counting guard (after Drake's LimitMalloc) for the
// "no allocation after the first Factorize()" promise of the interface.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "linear_solver_matrices.h"
#include "linalg/linear_solver.h"
#include "models/models.h"
#include "solvers/solver.h"
#include "tracking/tracker.h"

namespace snapthread {
namespace {

// Allocation counting: tests/support/allocation_counter.h.
using test_support::AllocationCounter;
using test_support::MallocsDuring;
using namespace test_matrices;

// ---------------------------------------------------------------------------------
// One body per backend.

class LinearSolverTest : public ::testing::TestWithParam<std::string> {
 protected:
  std::unique_ptr<SymmetricLinearSolver> Make() {
    std::string error;
    auto solver = MakeLinearSolver(GetParam(), 0, -1, &error);
    EXPECT_NE(solver, nullptr) << error;
    return solver;
  }

  // Analyze + Factorize + Solve of a, compared with a dense LU solve of the same system.
  void ExpectSolves(const Mat& dense, const SparseMatrix& a, int expected_negative,
                    double tolerance, std::mt19937* rng) {
    const int n = static_cast<int>(dense.rows());
    auto solver = Make();
    ASSERT_EQ(solver->Analyze(a), LinearSolverStatus::kSuccess) << solver->message();
    ASSERT_EQ(solver->Factorize(a), LinearSolverStatus::kSuccess) << solver->message();
    EXPECT_EQ(solver->message(), "");
    EXPECT_EQ(solver->NegativePivots(), expected_negative);
    const Vec b = RandomVector(n, rng);
    Vec x;
    ASSERT_EQ(solver->Solve(b, &x), LinearSolverStatus::kSuccess);
    ASSERT_EQ(x.size(), n);
    const Vec reference = Eigen::FullPivLU<Mat>(dense).solve(b);
    EXPECT_LT(RelativeError(x, reference), tolerance) << "n = " << n;
  }
};

TEST_P(LinearSolverTest, SolvesRandomSpdBandMatrices) {
  std::mt19937 rng(1);
  for (int n : {1, 2, 7, 50, 300}) {
    for (int b : {0, 1, 2, 8}) {
      const int band = std::min(b, n - 1);
      SCOPED_TRACE("n = " + std::to_string(n) + ", b = " + std::to_string(band));
      const Mat dense = RandomSpdBand(n, band, &rng);
      const SparseMatrix a = BandToSparse(dense, band);
      ExpectSolves(dense, a, 0, 1e-12, &rng);
    }
  }
}

// For SPD A every pivot of LDL^T (in any symmetric ordering) is a diagonal entry of a
// Schur complement, so lambda_min(A) <= min |d_i| <= lambda_max(A).
TEST_P(LinearSolverTest, MinAbsPivotOfSpdMatrixLiesInSpectrum) {
  std::mt19937 rng(2);
  for (int n : {1, 7, 50}) {
    const Mat dense = RandomSpdBand(n, std::min(2, n - 1), &rng);
    const SparseMatrix a = BandToSparse(dense, std::min(2, n - 1));
    auto solver = Make();
    ASSERT_EQ(solver->Analyze(a), LinearSolverStatus::kSuccess);
    ASSERT_EQ(solver->Factorize(a), LinearSolverStatus::kSuccess);
    const Vec lambda = Eigen::SelfAdjointEigenSolver<Mat>(dense).eigenvalues();
    EXPECT_GE(solver->MinAbsPivot(), lambda.minCoeff() * (1 - 1e-12)) << "n = " << n;
    EXPECT_LE(solver->MinAbsPivot(), lambda.maxCoeff() * (1 + 1e-12)) << "n = " << n;
  }
}

TEST_P(LinearSolverTest, InertiaOfIndefiniteDenseMatrices) {
  std::mt19937 rng(3);
  for (int n : {1, 2, 5, 7, 12}) {
    for (int negative = 0; negative <= n; ++negative) {
      SCOPED_TRACE("n = " + std::to_string(n) + ", negative = " + std::to_string(negative));
      const Mat dense = RandomWithInertia(n, negative, &rng);
      ExpectSolves(dense, BandToSparse(dense, n - 1), negative, 1e-8, &rng);
    }
  }
}

// Chains: random tri-/pentadiagonal T shifted to A = T - sigma I with sigma halfway
// between two eigenvalues of T, so A has exactly k negative eigenvalues.
TEST_P(LinearSolverTest, InertiaOfShiftedBandMatrices) {
  std::mt19937 rng(4);
  for (int n : {7, 50, 300}) {
    for (int b : {1, 2}) {
      const Mat t = RandomSymmetricBand(n, b, &rng);
      const Vec lambda = Eigen::SelfAdjointEigenSolver<Mat>(t).eigenvalues();  // ascending
      for (int k : {0, 1, 2, n / 2, n}) {
        SCOPED_TRACE("n = " + std::to_string(n) + ", b = " + std::to_string(b) +
                     ", k = " + std::to_string(k));
        double sigma;
        if (k == 0) {
          sigma = lambda[0] - 1.0;
        } else if (k == n) {
          sigma = lambda[n - 1] + 1.0;
        } else {
          sigma = 0.5 * (lambda[k - 1] + lambda[k]);
        }
        const Mat dense = t - sigma * Mat::Identity(n, n);
        // Unpivoted LDL^T of an indefinite matrix has no growth bound: allow some.
        ExpectSolves(dense, BandToSparse(dense, b), k, 1e-7, &rng);
      }
    }
  }
}

TEST_P(LinearSolverTest, RefactorizesWithNewValuesOnTheSamePattern) {
  std::mt19937 rng(5);
  const int n = 50, b = 2;
  auto solver = Make();
  const Mat first = RandomSpdBand(n, b, &rng);
  ASSERT_EQ(solver->Analyze(BandToSparse(first, b)), LinearSolverStatus::kSuccess);
  const Vec rhs = RandomVector(n, &rng);
  Vec x;
  for (int round = 0; round < 4; ++round) {
    // Alternate definite and indefinite values on one pattern.
    const Mat dense = round % 2 == 0 ? RandomSpdBand(n, b, &rng) : Mat(-RandomSpdBand(n, b, &rng));
    ASSERT_EQ(solver->Factorize(BandToSparse(dense, b)), LinearSolverStatus::kSuccess)
        << solver->message();
    EXPECT_EQ(solver->NegativePivots(), round % 2 == 0 ? 0 : n);
    ASSERT_EQ(solver->Solve(rhs, &x), LinearSolverStatus::kSuccess);
    const Vec reference = Eigen::FullPivLU<Mat>(dense).solve(rhs);
    EXPECT_LT(RelativeError(x, reference), 1e-12) << "round " << round;
  }
}

// The matrices the backends exist for: thread3d Hessians (3 coordinates per node,
// half-bandwidth 8), straight and compressed (indefinite, many negative eigenvalues),
// with and without the grip direction. Inertia against the eigenvalues, solution
// against a dense LU.
TEST_P(LinearSolverTest, Thread3dHessians) {
  std::mt19937 rng(14);
  std::normal_distribution<double> noise(0.0, 0.02);
  int checked = 0;
  for (int segments : {4, 12, 40}) {
    for (bool grip : {false, true}) {
      for (double compression : {1.0, 0.9, 0.6}) {
        ModelParams p;
        p.model = "thread3d";
        p.Set("n", segments);
        p.Set("grip_direction", grip);
        const auto model = MakeModel(p);
        Vec u = Vec::Zero(model->NumControls());
        u[0] = compression * segments * p.Number("segment_length");
        if (grip) u[3] = 1.0;
        Vec x = model->InitialState(u);
        for (int i = 0; i < x.size(); ++i) x[i] += noise(rng);
        SparseMatrix h = model->HessianPattern();
        model->Hessian(x, u, &h);
        const Mat dense = Mat(h);
        const Vec lambda = Eigen::SelfAdjointEigenSolver<Mat>(dense).eigenvalues();
        // The inertia is well defined only away from a zero eigenvalue.
        if (lambda.cwiseAbs().minCoeff() < 1e-8 * lambda.cwiseAbs().maxCoeff()) continue;
        const int negative = static_cast<int>((lambda.array() < 0.0).count());
        SCOPED_TRACE("segments = " + std::to_string(segments) + ", grip = " +
                     std::to_string(grip) + ", compression = " + std::to_string(compression));
        ExpectSolves(dense, h, negative, 1e-7, &rng);
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 12);  // most cases are regular; the guard above is not the rule
}

// Analyze() again with another pattern (other size and band) replaces the old one.
TEST_P(LinearSolverTest, ReanalyzesForANewPattern) {
  std::mt19937 rng(13);
  auto solver = Make();
  Vec x;
  for (const auto& [n, b] : std::vector<std::pair<int, int>>{{50, 2}, {7, 1}, {120, 8}, {50, 2}}) {
    SCOPED_TRACE("n = " + std::to_string(n) + ", b = " + std::to_string(b));
    const Mat dense = RandomSpdBand(n, b, &rng);
    const SparseMatrix a = BandToSparse(dense, b);
    ASSERT_EQ(solver->Analyze(a), LinearSolverStatus::kSuccess) << solver->message();
    ASSERT_EQ(solver->Factorize(a), LinearSolverStatus::kSuccess) << solver->message();
    const Vec rhs = RandomVector(n, &rng);
    ASSERT_EQ(solver->Solve(rhs, &x), LinearSolverStatus::kSuccess);
    EXPECT_LT(RelativeError(x, Eigen::FullPivLU<Mat>(dense).solve(rhs)), 1e-12);
  }
}

// Every backend reads the lower triangle only, so they agree on a (wrongly) asymmetric
// input: the answer is that of the matrix symmetrised from its lower triangle.
TEST_P(LinearSolverTest, ReadsOnlyTheLowerTriangle) {
  std::mt19937 rng(12);
  const int n = 20, b = 3;
  const Mat lower_spd = RandomSpdBand(n, b, &rng);
  Mat skewed = lower_spd;
  const Mat junk = RandomSymmetricBand(n, b, &rng);
  skewed.triangularView<Eigen::StrictlyUpper>() = junk.triangularView<Eigen::StrictlyUpper>();
  ASSERT_GT((skewed - lower_spd).norm(), 0.1);
  ExpectSolves(lower_spd, BandToSparse(skewed, b), 0, 1e-12, &rng);
}

TEST_P(LinearSolverTest, UncompressedStorageGivesTheSameSolution) {
  std::mt19937 rng(6);
  const int n = 30, b = 2;
  const Mat dense = RandomSpdBand(n, b, &rng);
  SparseMatrix a(n, n);
  a.reserve(Eigen::VectorXi::Constant(n, 2 * b + 3));  // leaves gaps: not compressed
  for (int j = 0; j < n; ++j) {
    for (int i = std::max(0, j - b); i <= std::min(n - 1, j + b); ++i) {
      a.insert(i, j) = dense(i, j);
    }
  }
  ASSERT_FALSE(a.isCompressed());
  ExpectSolves(dense, a, 0, 1e-12, &rng);
  // A solver analysed on the compressed form accepts the uncompressed one (same pattern).
  auto solver = Make();
  ASSERT_EQ(solver->Analyze(BandToSparse(dense, b)), LinearSolverStatus::kSuccess);
  EXPECT_EQ(solver->Factorize(a), LinearSolverStatus::kSuccess) << solver->message();
}

TEST_P(LinearSolverTest, SingularMatrixIsNumericalIssue) {
  std::mt19937 rng(7);
  // Singular matrices whose zero pivot is exact in every elimination order: the Path
  // Laplacian (integer arithmetic until the last pivot, at least in band order), the zero
  // matrix, and matrices with one zero row and column (its Schur complement entry stays
  // exactly 0 whatever is eliminated before it), definite and indefinite. A matrix that
  // is singular only up to round-off (Q diag(lambda) Q^T with one lambda = 0) gives a
  // pivot of 1e-16..1e-11 * max|a_ij|; kSingularPivotTolerance = 1e-14 catches ~96% of
  // those (measured on 2000 random 6x6): that is a heuristic, so it is not asserted here.
  std::vector<Mat> singular = {PathLaplacian(7), PathLaplacian(50), Mat::Zero(3, 3)};
  {
    Mat indefinite = RandomWithInertia(7, 3, &rng);
    indefinite.row(3).setZero();
    indefinite.col(3).setZero();
    singular.push_back(indefinite);
    Mat spd = RandomSpdBand(50, 2, &rng);
    spd.row(20).setZero();
    spd.col(20).setZero();
    singular.push_back(spd);
  }
  for (const Mat& dense : singular) {
    const int n = static_cast<int>(dense.rows());
    SCOPED_TRACE("n = " + std::to_string(n));
    const SparseMatrix a = BandToSparse(dense, n - 1);
    auto solver = Make();
    ASSERT_EQ(solver->Analyze(a), LinearSolverStatus::kSuccess);
    EXPECT_EQ(solver->Factorize(a), LinearSolverStatus::kNumericalIssue);
    EXPECT_NE(solver->message(), "");
    // No stale or partial factor is used afterwards.
    Vec x;
    EXPECT_EQ(solver->Solve(Vec::Ones(n), &x), LinearSolverStatus::kInvalidInput);
  }
  // A non-finite entry is a numerical issue too, and a good matrix afterwards recovers.
  const Mat good = RandomSpdBand(7, 1, &rng);
  Mat bad = good;
  bad(3, 3) = std::numeric_limits<double>::quiet_NaN();
  auto solver = Make();
  ASSERT_EQ(solver->Analyze(BandToSparse(good, 1)), LinearSolverStatus::kSuccess);
  EXPECT_EQ(solver->Factorize(BandToSparse(bad, 1)), LinearSolverStatus::kNumericalIssue);
  EXPECT_NE(solver->message(), "");
  EXPECT_EQ(solver->Factorize(BandToSparse(good, 1)), LinearSolverStatus::kSuccess);
  EXPECT_EQ(solver->message(), "");
}

TEST_P(LinearSolverTest, PatternOrSizeMismatchIsInvalidInput) {
  std::mt19937 rng(8);
  const Mat dense = RandomSpdBand(8, 2, &rng);
  const SparseMatrix analysed = BandToSparse(dense, 1);
  auto solver = Make();
  ASSERT_EQ(solver->Analyze(analysed), LinearSolverStatus::kSuccess);
  // Wider band.
  EXPECT_EQ(solver->Factorize(BandToSparse(dense, 2)), LinearSolverStatus::kInvalidInput);
  EXPECT_NE(solver->message(), "");
  // Other size.
  EXPECT_EQ(solver->Factorize(BandToSparse(RandomSpdBand(9, 1, &rng), 1)),
            LinearSolverStatus::kInvalidInput);
  // Same size and number of nonzeros, entries elsewhere: move the coupling (0,1) to (0,7).
  {
    std::vector<Eigen::Triplet<double>> t;
    for (int j = 0; j < 8; ++j) {
      for (SparseMatrix::InnerIterator it(analysed, j); it; ++it) {
        int r = it.row(), c = it.col();
        if (r + c == 1 && r != c) (r == 0 ? c : r) = 7;
        t.emplace_back(r, c, it.value());
      }
    }
    SparseMatrix moved(8, 8);
    moved.setFromTriplets(t.begin(), t.end());
    ASSERT_EQ(moved.nonZeros(), analysed.nonZeros());
    EXPECT_EQ(solver->Factorize(moved), LinearSolverStatus::kInvalidInput);
  }
  // The analysed pattern still works, and Solve checks the right-hand side's size.
  ASSERT_EQ(solver->Factorize(analysed), LinearSolverStatus::kSuccess) << solver->message();
  Vec x;
  EXPECT_EQ(solver->Solve(Vec::Ones(7), &x), LinearSolverStatus::kInvalidInput);
  EXPECT_EQ(solver->Solve(Vec::Ones(8), nullptr), LinearSolverStatus::kInvalidInput);
  EXPECT_EQ(solver->Solve(Vec::Ones(8), &x), LinearSolverStatus::kSuccess);
}

TEST_P(LinearSolverTest, CallsOutOfOrderAndBadPatternsAreInvalidInput) {
  std::mt19937 rng(9);
  const Mat dense = RandomSpdBand(5, 1, &rng);
  const SparseMatrix a = BandToSparse(dense, 1);
  Vec x;
  {
    auto solver = Make();
    EXPECT_EQ(solver->Factorize(a), LinearSolverStatus::kInvalidInput);
    EXPECT_NE(solver->message(), "");
    EXPECT_EQ(solver->Solve(Vec::Ones(5), &x), LinearSolverStatus::kInvalidInput);
    ASSERT_EQ(solver->Analyze(a), LinearSolverStatus::kSuccess);
    EXPECT_EQ(solver->Solve(Vec::Ones(5), &x), LinearSolverStatus::kInvalidInput);
  }
  auto solver = Make();
  EXPECT_EQ(solver->Analyze(SparseMatrix(3, 4)), LinearSolverStatus::kInvalidInput);
  EXPECT_NE(solver->message(), "");
  EXPECT_EQ(solver->Analyze(SparseMatrix(0, 0)), LinearSolverStatus::kInvalidInput);
  // Only the lower triangle stored: not the full symmetric pattern the interface wants.
  const SparseMatrix lower = SparseMatrix(a.triangularView<Eigen::Lower>());
  EXPECT_EQ(solver->Analyze(lower), LinearSolverStatus::kInvalidInput);
  // A failed Analyze() leaves nothing to factorise.
  EXPECT_EQ(solver->Factorize(a), LinearSolverStatus::kInvalidInput);
}

// After a warm-up Factorize + Solve, repeated Factorize + Solve on the same pattern do
// not touch the heap (malloc, calloc, realloc or operator new), for every backend.
TEST_P(LinearSolverTest, RepeatedFactorizeAndSolveDoNotAllocate) {
  std::mt19937 rng(10);
  for (int n : {7, 300}) {
    const int b = std::min(8, n - 1);
    std::vector<SparseMatrix> matrices;
    for (int k = 0; k < 4; ++k) {
      Mat dense = RandomSpdBand(n, b, &rng);
      if (k % 2 == 1) dense.diagonal().array() -= 0.5 * dense.diagonal().mean();  // indefinite
      matrices.push_back(BandToSparse(dense, b));
    }
    const Vec rhs = RandomVector(n, &rng);
    Vec x(n);
    auto solver = Make();
    ASSERT_EQ(solver->Analyze(matrices[0]), LinearSolverStatus::kSuccess);
    ASSERT_EQ(solver->Factorize(matrices[0]), LinearSolverStatus::kSuccess);
    ASSERT_EQ(solver->Solve(rhs, &x), LinearSolverStatus::kSuccess);

    std::vector<LinearSolverStatus> statuses(2 * matrices.size());
    AllocationCounter counter;
    for (size_t k = 0; k < matrices.size(); ++k) {
      statuses[2 * k] = solver->Factorize(matrices[k]);
      statuses[2 * k + 1] = solver->Solve(rhs, &x);
    }
    counter.Stop();
    for (LinearSolverStatus s : statuses) EXPECT_EQ(s, LinearSolverStatus::kSuccess);
    EXPECT_EQ(counter.mallocs(), 0) << "n = " << n;
    EXPECT_EQ(counter.news(), 0) << "n = " << n;
  }
}

// The equilibrium solvers built on these backends keep their workspace from the first
// solve (SolverBase): later solves along a path do not touch the heap either, for every
// method and backend.
TEST_P(LinearSolverTest, EquilibriumSolvesAfterTheFirstDoNotAllocate) {
  ModelParams p;
  p.model = "thread3d";
  p.Set("n", 12);
  auto model = MakeModel(p);
  for (const char* method : {"newton", "newton-ls", "higher-order"}) {
    SolverOptions o;
    o.method = method;
    o.linear_solver = GetParam();
    auto solver = MakeSolver(*model, o);
    Vec u = Vec::Zero(model->NumControls());
    u[0] = 0.8 * p.Integer("n");
    u[1] = 0.5;
    Vec x = model->InitialState(u);
    SolverOptions strict = o;
    strict.method = "newton-ls";
    strict.max_iterations = 0;
    MakeSolver(*model, strict)->Solve(u, &x);
    SolverSummary warm = solver->Solve(u, &x);
    ASSERT_TRUE(warm.IsConverged()) << method << ": " << warm.BriefReport();
    std::vector<Termination> terminations(10);
    AllocationCounter counter;
    for (int k = 0; k < 10; ++k) {
      u[1] += 0.01;
      terminations[k] = solver->Solve(u, &x).termination;
    }
    counter.Stop();
    for (Termination t : terminations) EXPECT_EQ(t, Termination::kConverged) << method;
    EXPECT_EQ(counter.mallocs(), 0) << method;
    EXPECT_EQ(counter.news(), 0) << method;
  }
}

// SolveMany() runs several right-hand sides at once (the implicit differentiation's
// E_xu columns): each column is Solve() of that column to the last bit, and repeated
// calls with the result already sized do not allocate.
TEST_P(LinearSolverTest, SolveManyEqualsSolvePerColumnWithoutAllocating) {
  std::mt19937 rng(11);
  for (int n : {1, 5, 9, 300}) {
    const int b = std::min(8, n - 1);
    Mat dense = RandomSpdBand(n, b, &rng);
    dense.diagonal().array() -= 0.3 * dense.diagonal().mean();  // indefinite
    const SparseMatrix a = BandToSparse(dense, b);
    auto solver = Make();
    ASSERT_EQ(solver->Analyze(a), LinearSolverStatus::kSuccess);
    ASSERT_EQ(solver->Factorize(a), LinearSolverStatus::kSuccess) << solver->message();
    Mat rhs(n, 3);
    for (int j = 0; j < 3; ++j) rhs.col(j) = RandomVector(n, &rng);
    Mat x;
    ASSERT_EQ(solver->SolveMany(rhs, &x), LinearSolverStatus::kSuccess);
    ASSERT_EQ(x.rows(), n);
    ASSERT_EQ(x.cols(), 3);
    for (int j = 0; j < 3; ++j) {
      Vec column;
      ASSERT_EQ(solver->Solve(rhs.col(j), &column), LinearSolverStatus::kSuccess);
      for (int i = 0; i < n; ++i) ASSERT_EQ(x(i, j), column[i]) << "n = " << n << ", column " << j << ", row " << i;
    }
    EXPECT_EQ(solver->SolveMany(rhs, &rhs), LinearSolverStatus::kInvalidInput);
    LinearSolverStatus again = LinearSolverStatus::kInvalidInput;
    EXPECT_EQ(MallocsDuring([&] { again = solver->SolveMany(rhs, &x); }), 0) << "n = " << n;
    EXPECT_EQ(again, LinearSolverStatus::kSuccess);
  }
}

// A whole tracker update (predictor, solve, F and K by implicit differentiation) does
// not touch the heap once the tracker has run its first updates, for every method and
// backend (the 1 kHz device never waits on it, but the server's solve loop should not
// allocate per pose either).
TEST_P(LinearSolverTest, TrackerUpdatesAfterTheFirstDoNotAllocate) {
  ModelParams p;
  p.model = "thread3d";
  p.Set("n", 12);
  for (const char* method : {"newton", "newton-ls", "higher-order"}) {
    SolverOptions o;
    o.method = method;
    o.linear_solver = GetParam();
    EquilibriumTracker tracker(MakeModel(p), o);
    Vec u = Vec::Zero(3);
    u << 0.8 * p.Integer("n"), 0.5, 0.1;
    tracker.Reset(u);
    for (int k = 0; k < 3; ++k) {
      u[1] += 0.01;
      tracker.Update(u);
    }
    std::vector<Termination> terminations(20);
    AllocationCounter counter;
    for (int k = 0; k < 20; ++k) {
      u[1] += 0.01;
      u[2] -= 0.005;
      terminations[k] = tracker.Update(u).summary.termination;
    }
    counter.Stop();
    for (Termination t : terminations) EXPECT_EQ(t, Termination::kConverged) << method;
    EXPECT_EQ(counter.mallocs(), 0) << method;
    EXPECT_EQ(counter.news(), 0) << method;
  }
}

std::vector<std::string> ConcreteBackends() { return {"cholmod", "dense", "banded"}; }
INSTANTIATE_TEST_SUITE_P(Backends, LinearSolverTest, ::testing::ValuesIn(ConcreteBackends()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

}  // namespace
}  // namespace snapthread
