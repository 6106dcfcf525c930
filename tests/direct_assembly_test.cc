// Direct assembly of E_xx into the banded factorisation's storage (issue 13 item 3):
// a chain model writes the lower band straight where BandedLdlt factorises it, skipping
// the compressed matrix and the copy out of it. Both halves must give what the
// compressed path gives, to the last bit: the model's band holds Hessian()'s values, and
// FactorizeAssembled() the factor of Factorize().
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/SparseCore>

#include "allocation_counter.h"
#include "band_check.h"
#include "linalg/banded_ldlt.h"
#include "linalg/linear_solver.h"
#include "models/models.h"

namespace snapthread {
namespace {

using test_support::AllocationCounter;

// Symmetric, diagonally dominant shifted to indefinite, half-bandwidth b, with holes:
// the entries (i, i - b) of rows i = 1 mod 3 are left out of the pattern (slots inside
// the band that take fill-in, as in a thread3d Hessian).
SparseMatrix HoledBand(int n, int b, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < n; ++j) {
    double row = 0.0;
    for (int i = j + 1; i <= std::min(n - 1, j + b); ++i) {
      if (b > 1 && i - j == b && i % 3 == 1) continue;
      const double v = u(*rng);
      t.emplace_back(i, j, v);
      t.emplace_back(j, i, v);
      row += 2.0 * std::abs(v);
    }
    t.emplace_back(j, j, (j % 4 == 1 ? -1.0 : 1.0) * (1.0 + row + 2.0 * b));
  }
  SparseMatrix a(n, n);
  a.setFromTriplets(t.begin(), t.end());
  a.makeCompressed();
  return a;
}

TEST(LinearDirectAssembly, FactorizeAssembledEqualsFactorizeOfTheCompressedMatrix) {
  std::mt19937 rng(23);
  for (int n : {1, 4, 9, 40, 300}) {
    const int b = std::min(8, n - 1);
    const SparseMatrix a = HoledBand(n, b, &rng);
    BandedLdlt reference, direct;
    ASSERT_EQ(reference.Analyze(a), LinearSolverStatus::kSuccess);
    ASSERT_EQ(direct.Analyze(a), LinearSolverStatus::kSuccess);
    ASSERT_EQ(reference.Factorize(a), LinearSolverStatus::kSuccess) << reference.message();
    // A first factorisation leaves fill-in in the holes of the direct backend's band:
    // FactorizeAssembled() must clear it.
    ASSERT_EQ(direct.Factorize(a), LinearSolverStatus::kSuccess);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Vec rhs(n);
    for (int i = 0; i < n; ++i) rhs[i] = u(rng);
    Vec x_ref(n), x(n);
    ASSERT_EQ(reference.Solve(rhs, &x_ref), LinearSolverStatus::kSuccess);

    int bandwidth = -1;
    AllocationCounter counter;
    double* band = direct.AssemblyBand(&bandwidth);
    const bool stale = direct.Solve(rhs, &x) == LinearSolverStatus::kInvalidInput;
    for (int j = 0; band != nullptr && j < n; ++j) {
      for (SparseMatrix::InnerIterator it(a, j); it; ++it) {
        if (it.row() >= j) band[it.row() * (bandwidth + 1) + j - it.row() + bandwidth] = it.value();
      }
    }
    const LinearSolverStatus st = direct.FactorizeAssembled();
    const LinearSolverStatus solved = direct.Solve(rhs, &x);
    counter.Stop();
    ASSERT_NE(band, nullptr);
    ASSERT_EQ(bandwidth, b);
    EXPECT_TRUE(stale) << "the factor was handed out for assembly, yet still solves";
    ASSERT_EQ(st, LinearSolverStatus::kSuccess) << direct.message();
    ASSERT_EQ(solved, LinearSolverStatus::kSuccess);
    EXPECT_EQ(counter.mallocs(), 0) << "n = " << n;
    EXPECT_EQ(direct.NegativePivots(), reference.NegativePivots()) << "n = " << n;
    if (n > 1) {
      EXPECT_GT(direct.NegativePivots(), 0) << "n = " << n << ": meant to be indefinite";
    }
    EXPECT_EQ(direct.MinAbsPivot(), reference.MinAbsPivot()) << "n = " << n;
    for (int i = 0; i < n; ++i) ASSERT_EQ(x[i], x_ref[i]) << "n = " << n << ", row " << i;
  }
}

TEST(LinearDirectAssembly, SingularBandIsReportedAndOtherBackendsHaveNoBand) {
  Mat m = Mat::Identity(5, 5);
  m(2, 2) = 0.0;
  const SparseMatrix a = m.sparseView();
  SparseMatrix tri(5, 5);  // tridiagonal pattern, zeros off the diagonal
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < 5; ++i) {
    t.emplace_back(i, i, m(i, i));
    if (i > 0) t.emplace_back(i, i - 1, 0.0), t.emplace_back(i - 1, i, 0.0);
  }
  tri.setFromTriplets(t.begin(), t.end());
  tri.makeCompressed();
  BandedLdlt singular;
  ASSERT_EQ(singular.Analyze(tri), LinearSolverStatus::kSuccess);
  int b = -1;
  double* band = singular.AssemblyBand(&b);
  ASSERT_NE(band, nullptr);
  ASSERT_EQ(b, 1);
  for (int i = 0; i < 5; ++i) band[i * (b + 1) + b] = m(i, i);
  for (int i = 1; i < 5; ++i) band[i * (b + 1) + b - 1] = 0.0;
  EXPECT_EQ(singular.FactorizeAssembled(), LinearSolverStatus::kNumericalIssue);
  EXPECT_NE(singular.message().find("pivot 2"), std::string::npos) << singular.message();

  BandedLdlt unanalysed;
  EXPECT_EQ(unanalysed.AssemblyBand(&b), nullptr);
  EXPECT_EQ(unanalysed.FactorizeAssembled(), LinearSolverStatus::kInvalidInput);
  for (const char* name : {"dense", "cholmod"}) {
    std::string error;
    auto other = MakeLinearSolver(name, 5, 1, &error);
    ASSERT_TRUE(other) << error;
    ASSERT_EQ(other->Analyze(tri), LinearSolverStatus::kSuccess);
    EXPECT_EQ(other->AssemblyBand(&b), nullptr) << name;
    EXPECT_EQ(other->FactorizeAssembled(), LinearSolverStatus::kInvalidInput) << name;
  }
  (void)a;
}

// The chains (without self-contact) write every lower-triangle entry of their pattern at
// its band slot (over NaN-filled storage, so each is written) with Hessian()'s value (==,
// so a zero may differ in sign), zeros everywhere else, and give Energy() and Gradient()
// to the last bit; another bandwidth is refused. Other models, and a chain with
// self-contact, decline and write nothing.
TEST(ModelBandAssembly, ChainsWriteHessiansValuesIntoTheBand) {
  struct Case {
    std::string model;
    int n;
    bool grip;
    bool contact;
    bool banded;
  };
  // thread3d n = 40: mostly interior terms, which thread3d writes into the band itself.
  const std::vector<Case> cases = {{"thread3d", 7, false, false, true}, {"thread3d", 7, true, false, true},
                                   {"thread3d", 40, false, false, true}, {"thread3d", 3, false, false, true},
                                   {"curve2d", 9, false, false, true},  {"thread3d", 7, false, true, false},
                                   {"zeeman", 0, false, false, false}};
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (const Case& c : cases) {
    ModelParams p;
    p.model = c.model;
    if (c.n > 0) p.Set("n", c.n);
    if (c.grip) p.Set("grip_direction", true);
    if (c.contact) p.Set("contact", true);
    auto model = MakeModel(p);
    const Model& m = *model;
    Vec u = Vec::Zero(m.NumControls());
    if (c.n > 0) {
      u[0] = 0.7 * c.n;
      u[1] = 0.4;
      if (c.grip) u.tail<3>() << 1.0, 0.2, 0.1;
    } else {
      u[0] = 0.3;
    }
    Vec x = m.InitialState(u);
    for (int i = 0; i < x.size(); ++i) x[i] += noise(rng);
    const test_support::SeparateValues separate = test_support::EvaluateSeparately(m, x, u);
    const int b = m.HessianBandwidth();
    const test_support::BandAssembly fused = test_support::AssembleBand(m, x, u, b);
    ASSERT_EQ(fused.written, c.banded) << c.model << (c.contact ? " with contact" : "");
    if (!fused.written) {
      EXPECT_TRUE(fused.Untouched()) << c.model << ": a declining model wrote the band";
      continue;
    }
    test_support::ExpectBandHoldsSeparateValues(fused, b, separate, c.model);
    const test_support::BandAssembly wider = test_support::AssembleBand(m, x, u, b + 1);
    EXPECT_FALSE(wider.written) << c.model;
    EXPECT_TRUE(wider.Untouched()) << c.model << ": a declining model wrote the band";
  }
}

}  // namespace
}  // namespace snapthread
