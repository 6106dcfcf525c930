#include "snapthread/solver.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "higher_order_solver.h"
#include "newton_solver.h"

namespace snapthread {

const char* ToString(Method m) {
  switch (m) {
    case Method::kNewton: return "newton";
    case Method::kNewtonLineSearch: return "newton-ls";
    case Method::kHigherOrder: return "higher-order";
  }
  return "unknown";
}

bool ParseMethod(std::string_view name, Method* m) {
  if (name == "newton") *m = Method::kNewton;
  else if (name == "newton-ls") *m = Method::kNewtonLineSearch;
  else if (name == "higher-order") *m = Method::kHigherOrder;
  else return false;
  return true;
}

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

bool SolverOptions::IsValid(std::string* error) const {
  auto fail = [&](const char* m) {
    if (error) *error = m;
    return false;
  };
  if (!(cutoff > 0.0) || !std::isfinite(cutoff)) return fail("solver.cutoff: expected a finite number > 0");
  if (max_iterations < 0) return fail("solver.max_iterations: expected an integer >= 0 (0 = unlimited)");
  if (!(max_time_us >= 0.0) || !std::isfinite(max_time_us))
    return fail("solver.max_time_us: expected a finite number >= 0 (0 = none)");
  if (!(degeneracy_ratio > 0.0 && degeneracy_ratio < 1.0))
    return fail("solver.degeneracy_ratio: expected a number in (0, 1)");
  if (!(max_reduction_step > 0.0) || !std::isfinite(max_reduction_step))
    return fail("solver.max_reduction_step: expected a finite number > 0");
  std::string e;
  if (!MakeLinearSolver(linear_solver, 1, 0, &e))
    return fail("solver.linear_solver: expected one of auto, cholmod, dense, banded");
  return true;
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
