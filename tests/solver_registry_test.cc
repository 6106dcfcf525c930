// The solver registry: a method is one class plus one registration. A test-only toy
// method (gradient descent with a fixed step) is registered here and made and run
// through MakeSolver like the built-in ones; unknown names are clear errors.
#include <memory>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "models/models.h"
#include "solvers/registry.h"
#include "tracking/tracker.h"

namespace snapthread {
namespace {

// x <- x - step E_x(x, u) until |E_x| < cutoff or the budget is spent. No factorisation:
// Factorization() is null, so a tracker floors the stiffness (still finite).
class GradientDescentSolver final : public EquilibriumSolver {
 public:
  static constexpr double kStep = 0.1;
  GradientDescentSolver(const Model& model, const SolverOptions& options)
      : model_(model), options_(options), g_(model.NumStates()) {}
  const std::string& method() const override { return options_.method; }
  SolverSummary Solve(const Vec& u, Vec* x) override {
    SolverSummary s;
    if (x->size() != model_.NumStates() || u.size() != model_.NumControls()) {
      s.termination = Termination::kInvalidInput;
      return s;
    }
    const int budget = options_.max_iterations > 0 ? options_.max_iterations : SolverOptions::kUnlimitedIterations;
    for (;;) {
      model_.Gradient(*x, u, &g_);
      ++s.gradient_evaluations;
      s.residual = g_.norm();
      if (s.residual < options_.cutoff) {
        s.termination = Termination::kConverged;
        break;
      }
      if (s.iterations >= budget) break;
      *x -= kStep * g_;
      ++s.iterations;
    }
    s.energy = model_.Energy(*x, u);
    s.negative_pivots = -1;  // not factorised: the decision says near-fold
    s.status = DecideStatus(s, options_.degeneracy_ratio, false);
    return s;
  }
  void Reset() override {}
  const SymmetricLinearSolver* Factorization() const override { return nullptr; }
  const Vec& LowestEigenvector() const override { return empty_; }

 private:
  const Model& model_;
  SolverOptions options_;
  Vec g_, empty_;
};

void RegisterToyOnce() {
  SolverRegistry& r = SolverRegistry::Global();
  if (r.Find("test-gradient-descent") != nullptr) return;
  r.Register({"test-gradient-descent", "test only: gradient descent with a fixed step",
              [](const Model& m, const SolverOptions& o) { return std::make_unique<GradientDescentSolver>(m, o); }});
}

TEST(SolverRegistry, BuiltInsInRegistrationOrderWithDocs) {
  const SolverRegistry& r = SolverRegistry::Global();
  ASSERT_GE(r.Entries().size(), 3u);
  EXPECT_EQ(r.Entries()[0].name, "newton");
  EXPECT_EQ(r.Entries()[1].name, "newton-ls");
  EXPECT_EQ(r.Entries()[2].name, "higher-order");
  for (const SolverEntry& e : r.Entries()) {
    EXPECT_FALSE(e.doc.empty()) << e.name;
    EXPECT_EQ(e.doc.find('\n'), std::string::npos) << e.name << ": the doc is one line";
  }
  EXPECT_NE(r.Find(SolverOptions{}.method), nullptr) << "the default method is registered";
  EXPECT_EQ(r.Find("magic"), nullptr);
}

TEST(SolverRegistry, RejectsDuplicateAndIncompleteEntries) {
  SolverRegistry r;
  r.Register({"a", "first", [](const Model& m, const SolverOptions& o) { return std::make_unique<GradientDescentSolver>(m, o); }});
  EXPECT_THROW(r.Register({"a", "again", r.Entries()[0].make}), std::invalid_argument);
  EXPECT_THROW(r.Register({"", "no name", r.Entries()[0].make}), std::invalid_argument);
  EXPECT_THROW(r.Register({"b", "no factory", nullptr}), std::invalid_argument);
  r.Register({"b", "second", r.Entries()[0].make});
  r.Register({"c", "third", r.Entries()[0].make});
  EXPECT_EQ(r.NamesText(", ", " or "), "a, b or c");
}

TEST(SolverRegistry, UnknownMethodOrLinearSolverNamesTheFieldAndTheChoices) {
  auto model = MakeModel({.model = "cusp"});
  SolverOptions o;
  o.method = "magic";
  try {
    MakeSolver(*model, o);
    ADD_FAILURE() << "an unknown method was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("solver.method"), std::string::npos) << what;
    EXPECT_NE(what.find("'magic'"), std::string::npos) << what;
    EXPECT_NE(what.find("newton, newton-ls, higher-order"), std::string::npos) << what;
  }
  o = SolverOptions{};
  o.linear_solver = "magic";
  try {
    MakeSolver(*model, o);
    ADD_FAILURE() << "an unknown linear solver was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("solver.linear_solver"), std::string::npos) << what;
    EXPECT_NE(what.find("banded"), std::string::npos) << what;
  }
}

TEST(SolverRegistry, ToySolverRunsThroughMakeSolverAndTheTracker) {
  RegisterToyOnce();
  auto model = MakeModel({.model = "cusp"});
  SolverOptions o;
  o.method = "test-gradient-descent";
  o.max_iterations = 0;
  o.cutoff = 1e-8;
  auto solver = MakeSolver(*model, o);
  ASSERT_NE(dynamic_cast<GradientDescentSolver*>(solver.get()), nullptr);
  EXPECT_EQ(solver->method(), "test-gradient-descent");
  Vec u(2);
  u << -1.0, -1.0;
  Vec x = model->InitialState(u);
  const SolverSummary s = solver->Solve(u, &x);
  ASSERT_TRUE(s.IsConverged()) << s.BriefReport();
  EXPECT_GT(s.iterations, 5);
  // The same equilibrium as the built-in globalised Newton.
  SolverOptions ls;
  ls.method = "newton-ls";
  ls.cutoff = 1e-10;
  ls.max_iterations = 0;
  Vec xr = model->InitialState(u);
  ASSERT_TRUE(MakeSolver(*model, ls)->Solve(u, &xr).IsConverged());
  EXPECT_LT((x - xr).lpNorm<Eigen::Infinity>(), 1e-5);

  // Through the tracker as well: forces come out finite, K is floored (no factorisation).
  o.max_iterations = 2000;
  EquilibriumTracker tracker(MakeModel({.model = "cusp"}), o);
  tracker.Reset(u);
  for (int i = 1; i <= 5; ++i) {
    u[0] = -1.0 + 0.05 * i;
    const TrackResult& r = tracker.Update(u);
    EXPECT_TRUE(r.force.allFinite());
    EXPECT_TRUE(r.stiffness.allFinite());
    EXPECT_TRUE(r.stiffness_regularized);
    EXPECT_EQ(r.summary.status, EquilibriumStatus::kNearFold);
  }
}

}  // namespace
}  // namespace snapthread
