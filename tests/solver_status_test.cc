// The status of a solve is decided in one place (DecideStatus), and bad input to a
// solver is reported in its summary, not left to assertions that a Release build drops.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "models/models.h"
#include "solvers/solver.h"

namespace snapthread {
namespace {

SolverSummary Regular(double lambda_min, double lambda_ref) {
  SolverSummary s;
  s.termination = Termination::kConverged;
  s.lambda_min = lambda_min;
  s.lambda_ref = lambda_ref;
  s.negative_pivots = 0;
  return s;
}

TEST(DecideStatus, ReferenceEigenvalueInertiaAndBranchJump) {
  const double tau = 0.1;
  // Against the reference of the last regular state (DESIGN.md #1).
  EXPECT_EQ(DecideStatus(Regular(0.5, 1.0), tau, false), EquilibriumStatus::kRegular);
  EXPECT_EQ(DecideStatus(Regular(0.1, 1.0), tau, false), EquilibriumStatus::kNearFold);
  EXPECT_EQ(DecideStatus(Regular(0.09, 1.0), tau, false), EquilibriumStatus::kNearFold);
  // No reference yet: a positive eigenvalue is judged against itself (regular).
  EXPECT_EQ(DecideStatus(Regular(1e-6, -1.0), tau, false), EquilibriumStatus::kRegular);
  EXPECT_EQ(DecideStatus(Regular(0.0, -1.0), tau, false), EquilibriumStatus::kNearFold);
  // Indefinite or not factorised: near a fold whatever the eigenvalue estimate says.
  SolverSummary s = Regular(0.5, 1.0);
  s.negative_pivots = 1;
  EXPECT_EQ(DecideStatus(s, tau, false), EquilibriumStatus::kNearFold);
  s.negative_pivots = -1;
  EXPECT_EQ(DecideStatus(s, tau, false), EquilibriumStatus::kNearFold);
  // A jump to another branch outranks both.
  EXPECT_EQ(DecideStatus(s, tau, true), EquilibriumStatus::kSnapped);
  EXPECT_EQ(DecideStatus(Regular(0.5, 1.0), tau, true), EquilibriumStatus::kSnapped);
  // The loop's degeneracy test is the same rule.
  EXPECT_TRUE(NearFold(0.1, 0, 1.0, tau));
  EXPECT_FALSE(NearFold(0.2, 0, 1.0, tau));
}

TEST(DecideStatus, SolversReportTheDecidedStatus) {
  // The summary a solver returns carries the evidence, and its status is the decision
  // on that evidence, for every method.
  auto model = MakeModel({.model = "cusp"});
  for (const char* method : {"newton", "newton-ls", "higher-order"}) {
    SolverOptions o;
    o.method = method;
    auto solver = MakeSolver(*model, o);
    Vec u(2);
    Vec x = model->InitialState(Vec::Zero(2));
    for (int i = 0; i <= 20; ++i) {
      u << -1.0 + 0.1 * i, 0.4;
      const SolverSummary s = solver->Solve(u, &x);
      EXPECT_EQ(s.status, DecideStatus(s, o.degeneracy_ratio, false)) << method << " step " << i;
    }
  }
}

TEST(SolverInput, BadSizesAndNonFiniteInputAreReportedInTheSummary) {
  auto model = MakeModel([] {
    ModelParams p;
    p.model = "curve2d";
    p.Set("n", 6);
    return p;
  }());
  for (const char* method : {"newton", "newton-ls", "higher-order"}) {
    SolverOptions o;
    o.method = method;
    auto solver = MakeSolver(*model, o);
    Vec u(2);
    u << 5.5, 0.5;
    Vec x = model->InitialState(u);
    Vec wrong = Vec::Zero(x.size() + 1);
    SolverSummary s = solver->Solve(u, &wrong);
    EXPECT_EQ(s.termination, Termination::kInvalidInput) << method;
    EXPECT_FALSE(s.IsSolutionUsable());
    EXPECT_NE(s.message.find("state"), std::string::npos) << s.message;
    EXPECT_EQ(wrong.size(), x.size() + 1);

    s = solver->Solve(Vec::Zero(3), &x);
    EXPECT_EQ(s.termination, Termination::kInvalidInput) << method;
    EXPECT_NE(s.message.find("controls"), std::string::npos) << s.message;

    Vec nan_u = u;
    nan_u[1] = std::numeric_limits<double>::quiet_NaN();
    const Vec before = x;
    s = solver->Solve(nan_u, &x);
    EXPECT_EQ(s.termination, Termination::kInvalidInput) << method;
    EXPECT_EQ(x, before) << "the state must be left as it was";
    EXPECT_NE(std::string(s.BriefReport()).find("invalid-input"), std::string::npos);

    // The solver is still usable afterwards.
    s = solver->Solve(u, &x);
    EXPECT_TRUE(s.IsConverged()) << method << ": " << s.BriefReport();
  }
}

}  // namespace
}  // namespace snapthread
