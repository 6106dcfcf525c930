#include "solvers/registry.h"

#include <stdexcept>

#include "solvers/higher_order_solver.h"
#include "solvers/newton_solver.h"

namespace snapthread {
namespace {

template <typename S, auto... args>
std::unique_ptr<EquilibriumSolver> Make(const Model& model, const SolverOptions& options) {
  return std::make_unique<S>(model, options, args...);
}

// The built-in methods: one line each. The first is the seed's baseline; the order is
// the order of help texts, CSV charts and the stability suite.
SolverRegistry MakeBuiltIns() {
  SolverRegistry r;
  r.Register({"newton", "the seed's plain Newton (2.18): solve E_xx d = -E_x, no line search", Make<NewtonSolver, false>});
  r.Register({"newton-ls", "Newton with an inertia-corrected Hessian and Armijo backtracking", Make<NewtonSolver, true>});
  r.Register({"higher-order", "bifurcation-aware: Newton where E_xx is regular, the 4th-order reduction near folds (§2.4)", Make<HigherOrderSolver>});
  return r;
}

}  // namespace

SolverRegistry& SolverRegistry::Global() {
  static SolverRegistry registry = MakeBuiltIns();
  return registry;
}

void SolverRegistry::Register(SolverEntry entry) {
  if (entry.name.empty()) throw std::invalid_argument("SolverRegistry: empty solver name");
  if (!entry.make) throw std::invalid_argument("SolverRegistry: solver '" + entry.name + "' has no factory");
  if (Find(entry.name) != nullptr)
    throw std::invalid_argument("SolverRegistry: solver '" + entry.name + "' is already registered");
  entries_.push_back(std::move(entry));
}

const SolverEntry* SolverRegistry::Find(std::string_view name) const {
  for (const SolverEntry& e : entries_) {
    if (e.name == name) return &e;
  }
  return nullptr;
}

std::vector<std::string> SolverRegistry::Names() const {
  std::vector<std::string> names;
  for (const SolverEntry& e : entries_) names.push_back(e.name);
  return names;
}

std::string SolverRegistry::NamesText(std::string_view separator, std::string_view last_separator) const {
  std::string text;
  for (size_t i = 0; i < entries_.size(); ++i) {
    if (i > 0) text += i + 1 == entries_.size() ? last_separator : separator;
    text += entries_[i].name;
  }
  return text;
}

}  // namespace snapthread
