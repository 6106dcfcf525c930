// Solver behaviour: convergence rates, agreement between methods, the reduced quartic.
#include <cmath>

#include <gtest/gtest.h>

#include "solvers/higher_order_solver.h"
#include "models/models.h"
#include "solvers/solver.h"

namespace snapthread {
namespace {

ModelParams Curve(int n) {
  ModelParams p;
  p.model = "curve2d";
  p.Set("n", n);
  return p;
}

TEST(SolverOptions, IsValidNamesTheField) {
  SolverOptions o;
  std::string e;
  EXPECT_TRUE(o.IsValid(&e));
  o.cutoff = -1;
  EXPECT_FALSE(o.IsValid(&e));
  EXPECT_NE(e.find("cutoff"), std::string::npos);
  // Names are checked where the solver is made (the options carry no solver code).
  o = SolverOptions{};
  o.linear_solver = "magic";
  try {
    MakeSolver(*MakeModel({.model = "cusp"}), o);
    ADD_FAILURE() << "an unknown linear solver was accepted";
  } catch (const std::invalid_argument& ex) {
    EXPECT_NE(std::string(ex.what()).find("linear_solver"), std::string::npos) << ex.what();
    EXPECT_NE(std::string(ex.what()).find("magic"), std::string::npos) << ex.what();
  }
  o = SolverOptions{};
  o.max_iterations = -3;
  EXPECT_FALSE(o.IsValid(&e));
  EXPECT_NE(e.find("max_iterations"), std::string::npos);
  EXPECT_THROW(MakeSolver(*MakeModel({.model = "cusp"}), o), std::invalid_argument);
}

TEST(Newton, ConvergesQuadraticallyNearARegularMinimum) {
  // curve2d in tension: a regular minimum. Track |E_x| one iteration at a time.
  auto model = MakeModel(Curve(10));
  SolverOptions o;
  o.method = "newton";
  o.max_iterations = 1;
  o.cutoff = 1e-300;  // never "converged": run exactly one iteration per call
  auto solver = MakeSolver(*model, o);
  Vec u(2);
  u << 10.3, 0.5;
  Vec x = model->InitialState(u);
  // Start from a mildly perturbed equilibrium neighbourhood.
  SolverOptions strict;
  strict.method = "newton-ls";
  strict.max_iterations = 0;
  strict.cutoff = 1e-3;
  MakeSolver(*model, strict)->Solve(u, &x);
  std::vector<double> r;
  Vec g;
  model->Gradient(x, u, &g);
  r.push_back(g.norm());
  for (int i = 0; i < 4 && r.back() > 1e-13; ++i) {
    solver->Solve(u, &x);
    model->Gradient(x, u, &g);
    r.push_back(g.norm());
  }
  ASSERT_GE(r.size(), 3u);
  // Quadratic: r_{k+1} <= C r_k^2 with a moderate C once in the basin.
  for (size_t k = 1; k + 1 < r.size(); ++k) {
    if (r[k] < 1e-10) break;
    EXPECT_LT(r[k + 1], 1e3 * r[k] * r[k]) << "k=" << k;
  }
  EXPECT_LT(r.back(), 1e-10);
}

class MethodAgreement : public ::testing::TestWithParam<std::string> {};

TEST_P(MethodAgreement, SameEquilibriumAtRegularPoints) {
  for (const std::string name : {"curve2d", "thread3d"}) {
    ModelParams p;
    p.model = name;
    p.Set("n", 8);
    auto model = MakeModel(p);
    Vec u = Vec::Zero(model->NumControls());
    u[0] = 7.5;
    u[1] = 1.5;
    if (u.size() == 3) u[2] = 0.7;
    SolverOptions o;
    o.method = GetParam();
    o.max_iterations = 0;
    o.cutoff = 1e-10;
    Vec x = model->InitialState(u);
    SolverOptions ls = o;
    ls.method = "newton-ls";
    Vec x_ref = x;
    const SolverSummary ref = MakeSolver(*model, ls)->Solve(u, &x_ref);
    ASSERT_TRUE(ref.IsConverged()) << ref.BriefReport();
    // Warm start near the reference (tracking), then solve with the method under test.
    x = x_ref + 1e-3 * Vec::Ones(x.size());
    const SolverSummary s = MakeSolver(*model, o)->Solve(u, &x);
    EXPECT_TRUE(s.IsConverged()) << name << ": " << s.BriefReport();
    EXPECT_LT((x - x_ref).lpNorm<Eigen::Infinity>(), 1e-7) << name;
    EXPECT_GT(s.lambda_min, 0.0) << name;
    EXPECT_EQ(s.negative_pivots, 0) << name;
  }
}

INSTANTIATE_TEST_SUITE_P(AllMethods, MethodAgreement,
                         ::testing::Values("newton", "newton-ls", "higher-order"),
                         [](const auto& info) {
                           std::string s = info.param;
                           for (char& c : s)
                             if (c == '-') c = '_';
                           return s;
                         });

TEST(NewtonLineSearch, DecreasesEnergyFromAFarStart) {
  auto model = MakeModel(Curve(12));
  Vec u(2);
  u << 10.0, -2.0;
  Vec x = model->InitialState(u);
  x += 0.3 * Vec::Ones(x.size());  // far from equilibrium
  SolverOptions o;
  o.method = "newton-ls";
  o.max_iterations = 1;
  o.cutoff = 1e-10;
  auto solver = MakeSolver(*model, o);
  double e = model->Energy(x, u);
  for (int i = 0; i < 200; ++i) {
    const SolverSummary s = solver->Solve(u, &x);
    const double e_new = model->Energy(x, u);
    EXPECT_LE(e_new, e + 1e-12) << "iteration " << i;
    e = e_new;
    if (s.IsConverged()) break;
  }
  Vec g;
  model->Gradient(x, u, &g);
  EXPECT_LT(g.norm(), 1e-10);
}

TEST(FollowedMinimum, KeepsATinyRootExact) {
  // phi1 = 4e-17 at a converged state: the root must stay ~ -phi1 / (2 phi2), not be
  // lost to round-off in the other, huge root.
  ReducedQuartic q{4e-17, 1.0, 1e-9, 0.0};
  double s = 1.0;
  ASSERT_TRUE(FollowedMinimum(q, 0.5, &s));
  EXPECT_NEAR(s, -2e-17, 1e-30);
}

TEST(FollowedMinimum, NoDownhillRootMeansSnap) {
  // phi = s (downhill to the left) + 0 s^2 + s^3 : slope 1 + 3 s^2 > 0 everywhere.
  ReducedQuartic q{1.0, 0.0, 1.0, 0.25};
  double s = 0.0;
  EXPECT_FALSE(FollowedMinimum(q, 0.5, &s));
  // Standard cusp before the fold: T^3 + Y T + X with a minimum nearby.
  ReducedQuartic q2{-0.1, 0.5, 0.2, 0.25};
  ASSERT_TRUE(FollowedMinimum(q2, 0.5, &s));
  EXPECT_GT(s, 0.0);
  // The refined root is a stationary point of the quartic.
  const double slope = q2.phi1 + 2 * q2.phi2 * s + 3 * q2.phi3 * s * s + 4 * q2.phi4 * s * s * s;
  EXPECT_NEAR(slope, 0.0, 1e-12);
}

TEST(FollowedMinimum, CapsFarMinima) {
  ReducedQuartic q{-1.0, 1e-6, 0.0, 0.0};  // root at s = 5e5: outside the expansion
  double s = 0.0;
  ASSERT_TRUE(FollowedMinimum(q, 0.5, &s));
  EXPECT_DOUBLE_EQ(s, 0.5);
}

TEST(HigherOrder, CuspStepIsTheExactQuarticMinimum) {
  // For the standard cusp the 4th-order Taylor step (§2.3.5) is exact: one reduction
  // step from the degenerate point lands on the equilibrium T^3 + Y T + X = 0.
  auto model = MakeModel({.model = "cusp"});
  SolverOptions o;
  o.method = "higher-order";
  o.cutoff = 1e-12;
  o.max_iterations = 3;
  auto solver = MakeSolver(*model, o);
  Vec u(2);
  u << -0.001, 0.0;  // at the cusp point: E_TT = 0 at T = 0
  Vec x = Vec::Zero(1);
  const SolverSummary s = solver->Solve(u, &x);
  EXPECT_TRUE(s.IsConverged()) << s.BriefReport();
  EXPECT_NEAR(x[0], std::cbrt(0.001), 1e-9);
  EXPECT_TRUE(s.used_reduction);
}

}  // namespace
}  // namespace snapthread
