#include "solvers/solver.h"

#include <stdexcept>

#include "solvers/higher_order_solver.h"
#include "solvers/newton_solver.h"

namespace snapthread {

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
      return std::make_unique<NewtonSolver>(model, options, false);
    case Method::kNewtonLineSearch:
      return std::make_unique<NewtonSolver>(model, options, true);
    case Method::kHigherOrder:
      return std::make_unique<HigherOrderSolver>(model, options);
  }
  throw std::invalid_argument("solver.method: unknown method");
}

}  // namespace snapthread
