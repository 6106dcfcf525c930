// Newton-type equilibrium solvers and the machinery every method shares.
#pragma once

#include <chrono>
#include <memory>

#include "solvers/eigen_tracking.h"
#include "solvers/solver.h"

namespace snapthread {

// State shared by all methods: the model, one Hessian with its fixed pattern, its
// factorisation (symbolic analysis done once), a second factorisation object for
// modified matrices with the same pattern (shifted or restricted), the tracked lowest
// eigenpair, and evaluation counters.
class SolverBase : public EquilibriumSolver {
 public:
  SolverBase(const Model& model, const SolverOptions& options);
  Method method() const override { return options_.method; }
  void Reset() override;
  const SymmetricLinearSolver* Factorization() const override {
    return factor_valid_ ? factor_.get() : nullptr;
  }
  const Vec& LowestEigenvector() const override { return eig_.vector(); }

 protected:
  using Clock = std::chrono::steady_clock;

  void BeginSolve(SolverSummary* s);
  bool BudgetLeft(const SolverSummary& s) const;
  double EvalGradient(const Vec& x, const Vec& u, Vec* g, SolverSummary* s) const;
  // Assembles E_xx at x into h_ and factorises it into factor_.
  LinearSolverStatus FactorAt(const Vec& x, const Vec& u, SolverSummary* s);
  // Factorises h_ + shift I into alt_factor_ (pattern includes the diagonal).
  LinearSolverStatus FactorShifted(double shift, SolverSummary* s);
  // Final bookkeeping at the returned state: factorisation for implicit
  // differentiation, lowest eigenpair, inertia, residual, energy, timing.
  // gradient_current: g_ already holds E_x(x) (saves one evaluation per update).
  void Finish(const Vec& x, const Vec& u, SolverSummary* s, bool gradient_current = false);
  // Newton-ls step: inertia-corrected Newton direction + Armijo backtracking from x
  // with gradient g. Returns false if no decrease could be found.
  bool GlobalizedStep(const Vec& u, Vec* x, Vec* g, SolverSummary* s);
  int Budget() const;
  // Takes the plain Newton step x -= dx_ (factor_ is E_xx at x) and records whether it
  // was small enough for Finish() to keep using factor_.
  void TakeNewtonStep(Vec* x);
  // Loop head shared by every method: stops on a non-finite residual (restoring the last
  // finite state), on convergence or when the budget is spent; otherwise counts the
  // iteration, remembers the state and returns true.
  bool NextIteration(double r, Vec* x, SolverSummary* s);
  // Loop tail: restore a non-finite state, Finish(), leave a saddle (globalised methods
  // only), Classify().
  void Conclude(const Vec& u, Vec* x, SolverSummary* s, bool leave_saddles);
  // Globalised minimisation to the cutoff past the iteration budget (a snap is finished
  // inside its control step, DESIGN.md #4). From a saddle, where the gradient vanishes,
  // it first leaves along the negative mode of E_xx (the side that lowers E).
  bool MinimizeFully(const Vec& u, Vec* x, SolverSummary* s);
  // After Finish(): a "converged" state with negative pivots is a saddle, not the
  // followed minimum. Leave it and minimise (counted as a snap); then Finish again.
  void LeaveSaddle(const Vec& u, Vec* x, SolverSummary* s);
  // Sets summary.status from the final eigenvalue against the reference lambda_0 of
  // the last regular converged state (DESIGN.md #1), and updates that reference.
  void Classify(SolverSummary* s);

  const Model& model_;
  SolverOptions options_;
  int n_;
  SparseMatrix h_, h_mod_;
  std::unique_ptr<SymmetricLinearSolver> factor_, alt_factor_;
  bool factor_valid_ = false;
  // factor_ holds E_xx at the state before the last, tiny, plain Newton step: Finish()
  // may use it instead of factorising again (see kReuseStep in newton_solver.cc).
  bool factor_before_tiny_step_ = false;
  double lambda_ref_ = -1.0;  // lambda_0 at the last regular converged state
  double best_residual_ = 0.0;  // stagnation tracking in NextIteration
  int stalled_iterations_ = 0;
  std::vector<int> diag_index_;  // position of (i,i) in h_.valuePtr()
  SmallestEigenpair eig_;
  Vec g_, dx_, trial_, last_good_, dx_scratch_;
  Clock::time_point start_;
};

// newton (2.18) and newton-ls.
class NewtonSolver final : public SolverBase {
 public:
  NewtonSolver(const Model& model, const SolverOptions& options);
  SolverSummary Solve(const Vec& u, Vec* x) override;
};

}  // namespace snapthread
