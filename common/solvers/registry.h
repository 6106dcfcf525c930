// The solver registry: every equilibrium method by name, with a one-line doc and a
// factory, like the model registry. MakeSolver looks names up here; help
// texts, the stability suite and the bench iterate it instead of spelling method lists.
// The built-in methods are registered in registry.cc, one line each; a test may add its
// own (a test-only solver) before it makes one.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "solvers/solver.h"

namespace snapthread {

using SolverFactory =
    std::function<std::unique_ptr<EquilibriumSolver>(const Model& model, const SolverOptions& options)>;

struct SolverEntry {
  std::string name;    // SolverOptions::method, e.g. "higher-order"
  std::string doc;     // one line, for --help
  SolverFactory make;
};

class SolverRegistry {
 public:
  // The process-wide registry, holding the built-in methods in registration order
  // (newton, newton-ls, higher-order). Not synchronised: register at start-up, before
  // any thread makes a solver.
  static SolverRegistry& Global();

  // Throws std::invalid_argument for an empty or already registered name or a missing
  // factory.
  void Register(SolverEntry entry);
  // nullptr for a name that is not registered.
  const SolverEntry* Find(std::string_view name) const;
  const std::vector<SolverEntry>& Entries() const { return entries_; }
  std::vector<std::string> Names() const;
  // The names in registration order joined by `separator`, the last two by
  // `last_separator`: NamesText(", ", " or ") = "newton, newton-ls or higher-order".
  std::string NamesText(std::string_view separator, std::string_view last_separator) const;

 private:
  std::vector<SolverEntry> entries_;
};

}  // namespace snapthread
