// The back-end factory (MakeLinearSolver: names, the "auto" rule) and the guard of the
// allocation tests in linear_solver_test.cc, which must be able to fail.
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "linalg/linear_solver.h"
#include "linear_solver_matrices.h"

namespace snapthread {
namespace {

using test_support::AllocationCounter;
using namespace test_matrices;

// The guard must be able to fail: it sees C++, Eigen and CHOLMOD allocations.
TEST(AllocationCounterTest, SeesEveryKindOfAllocation) {
  {
    AllocationCounter counter;
    std::vector<int>* v = new std::vector<int>(100);
    counter.Stop();
    delete v;
    EXPECT_GE(counter.news(), 2);
    EXPECT_GE(counter.mallocs(), 2);
  }
  {
    AllocationCounter counter;
    Vec* v = new Vec(100);  // the coefficients come from Eigen's aligned_malloc
    counter.Stop();
    delete v;
    EXPECT_GE(counter.mallocs(), 2);
  }
  {
    std::string error;
    auto solver = MakeLinearSolver("cholmod", 10, 1, &error);
    ASSERT_NE(solver, nullptr);
    const SparseMatrix a = BandToSparse(PathLaplacian(10) + Mat::Identity(10, 10), 1);
    AllocationCounter counter;
    const LinearSolverStatus s = solver->Analyze(a);
    counter.Stop();
    EXPECT_EQ(s, LinearSolverStatus::kSuccess);
    // cholmod_analyze's own mallocs are counted beyond the std::vectors of Analyze().
    EXPECT_GT(counter.mallocs(), counter.news());
  }
}

TEST(MakeLinearSolverTest, KnownNamesMakeSolversAndUnknownNamesSayWhy) {
  for (const std::string& name : LinearSolverNames()) {
    std::string error;
    EXPECT_NE(MakeLinearSolver(name, 100, 8, &error), nullptr) << name << ": " << error;
  }
  std::string error;
  EXPECT_EQ(MakeLinearSolver("lu", 10, 1, &error), nullptr);
  EXPECT_NE(error.find("lu"), std::string::npos);
  EXPECT_NE(error.find("cholmod"), std::string::npos);
  EXPECT_EQ(MakeLinearSolver("lu", 10, 1, nullptr), nullptr);
  EXPECT_STREQ(ToString(LinearSolverStatus::kSuccess), "success");
  EXPECT_STRNE(ToString(LinearSolverStatus::kNumericalIssue),
               ToString(LinearSolverStatus::kInvalidInput));
}

// The measured rule documented above MakeLinearSolver: band with 2b <= n -> banded,
// other small matrices -> dense, the rest (and unknown bandwidth) -> cholmod.
TEST(MakeLinearSolverTest, AutoFollowsTheDocumentedRule) {
  const auto picked = [](int n, int bandwidth) {
    std::string error;
    auto solver = MakeLinearSolver("auto", n, bandwidth, &error);
    return solver ? std::string(solver->Name()) : error;
  };
  EXPECT_EQ(picked(300, 8), "banded");
  EXPECT_EQ(picked(3000, 8), "banded");
  EXPECT_EQ(picked(16, 8), "banded");
  EXPECT_EQ(picked(10, 8), "dense");
  EXPECT_EQ(picked(30, 29), "dense");
  EXPECT_EQ(picked(20, -1), "dense");
  EXPECT_EQ(picked(100, 99), "cholmod");
  EXPECT_EQ(picked(1000, -1), "cholmod");
  EXPECT_EQ(picked(0, -1), "cholmod");
}

// "auto" hands out a concrete backend, whichever it is, and that backend solves a chain.
TEST(MakeLinearSolverTest, AutoPicksAWorkingBackendForEverySize) {
  std::mt19937 rng(11);
  for (int n : {3, 30, 300, 1500}) {
    for (int b : {2, 8, 40}) {
      if (b >= n) continue;
      std::string error;
      auto solver = MakeLinearSolver("auto", n, b, &error);
      ASSERT_NE(solver, nullptr) << error;
      EXPECT_NE(solver->Name(), "auto");
      const Mat dense = RandomSpdBand(n, b, &rng);
      const SparseMatrix a = BandToSparse(dense, b);
      ASSERT_EQ(solver->Analyze(a), LinearSolverStatus::kSuccess) << solver->message();
      ASSERT_EQ(solver->Factorize(a), LinearSolverStatus::kSuccess) << solver->message();
      const Vec rhs = RandomVector(n, &rng);
      Vec x;
      ASSERT_EQ(solver->Solve(rhs, &x), LinearSolverStatus::kSuccess);
      EXPECT_LT((dense * x - rhs).norm() / rhs.norm(), 1e-12)
          << "n = " << n << ", b = " << b << ", backend " << solver->Name();
    }
  }
}

}  // namespace
}  // namespace snapthread
