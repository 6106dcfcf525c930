#include "solvers/newton_solver.h"

#include <string>

namespace snapthread {

NewtonSolver::NewtonSolver(const Model& model, const SolverOptions& options, bool line_search)
    : SolverBase(model, options), line_search_(line_search) {}

SolverSummary NewtonSolver::Solve(const Vec& u, Vec* x) {
  SolverSummary s;
  if (!BeginSolve(u, *x, &s) || ContinueSnap(u, x, &s)) return s;
  double r = EvalGradientAtStart(*x, u, &s);
  s.termination = Termination::kBudgetSpent;
  while (NextIteration(r, u, x, &s)) {
    if (line_search_) {
      if (!GlobalizedStep(u, x, &s)) {
        // No descent step at the gradient's round-off: converged.
        if (AtRoundOff(r, *x, u, &s)) {
          StopAtRoundOff(&s);
          break;
        }
        s.termination = Termination::kLinearSolverFailed;
        s.message = "no descent step found";
        break;
      }
    } else {
      // (2.18): linearise the field E_x at x_i, solve for its zero.
      if (FactorAt(*x, u, &s) != LinearSolverStatus::kSuccess ||
          ComputeNewtonStep() != LinearSolverStatus::kSuccess) {
        s.termination = Termination::kLinearSolverFailed;
        s.message = std::string("factorisation failed: ") + HessianFactor().message();
        break;
      }
      TakeNewtonStep(u, x);
    }
    // After any step but a tiny Newton one E_xx is needed at x next (the next iteration
    // or Finish()): one pass gives it with E_x.
    r = !line_search_ && LastStepTiny() ? EvalGradient(*x, u, &s) : EvalGradientAndHessian(*x, u, &s);
  }
  // Plain Newton (2.18) is kept as the seed's baseline: it may sit on a maximum or a
  // saddle (Fig 2.5). The globalised variant may not.
  Conclude(u, x, &s, line_search_);
  return s;
}

}  // namespace snapthread
