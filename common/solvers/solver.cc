#include "solvers/solver.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "solvers/higher_order_solver.h"
#include "solvers/newton_solver.h"

namespace snapthread {

const char* ToString(Termination t) {
  switch (t) {
    case Termination::kConverged: return "converged";
    case Termination::kBudgetSpent: return "budget-spent";
    case Termination::kLinearSolverFailed: return "linear-solver-failed";
    case Termination::kNonFinite: return "non-finite";
  }
  return "unknown";
}

const char* ToString(EquilibriumStatus s) {
  switch (s) {
    case EquilibriumStatus::kRegular: return "regular";
    case EquilibriumStatus::kNearFold: return "near-fold";
    case EquilibriumStatus::kSnapped: return "snapped";
  }
  return "unknown";
}

std::string SolverSummary::BriefReport() const {
  char buf[256];
  std::snprintf(buf, sizeof(buf),
                "%s (%s): %d iterations, |E_x| = %.3e, lambda_min = %.3e, %d negative pivots%s, %.1f us",
                ToString(termination), ToString(status), iterations, residual, lambda_min,
                negative_pivots, snapped ? ", snapped" : "", solve_us);
  std::string r = buf;
  if (!message.empty()) r += " — " + message;
  return r;
}

std::unique_ptr<EquilibriumSolver> MakeSolver(const Model& model, const SolverOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument(error);
  if (!MakeLinearSolver(options.linear_solver, 1, 0, &error)) {
    std::string names;
    for (const auto& n : LinearSolverNames()) names += (names.empty() ? "" : ", ") + n;
    throw std::invalid_argument("solver.linear_solver: expected one of " + names + ", got '" +
                                options.linear_solver + "'");
  }
  switch (options.method) {
    case Method::kNewton:
    case Method::kNewtonLineSearch:
      return std::make_unique<NewtonSolver>(model, options);
    case Method::kHigherOrder:
      return std::make_unique<HigherOrderSolver>(model, options);
  }
  throw std::invalid_argument("solver.method: unknown method");
}

}  // namespace snapthread
