#include "solvers/solver.h"

#include <stdexcept>

#include "solvers/registry.h"

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
  const SolverRegistry& registry = SolverRegistry::Global();
  const SolverEntry* entry = registry.Find(options.method);
  if (entry == nullptr) {
    throw std::invalid_argument("solver.method: expected one of " + registry.NamesText(", ", ", ") +
                                ", got '" + options.method + "'");
  }
  return entry->make(model, options);
}

}  // namespace snapthread
