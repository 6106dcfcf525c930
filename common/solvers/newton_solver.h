// Newton-type equilibrium solvers: newton (2.18) and newton-ls.
#pragma once

#include "solvers/solver_base.h"

namespace snapthread {

// newton (2.18) and newton-ls.
class NewtonSolver final : public SolverBase {
 public:
  NewtonSolver(const Model& model, const SolverOptions& options, bool line_search);
  SolverSummary Solve(const Vec& u, Vec* x) override;

 private:
  const bool line_search_;
};

}  // namespace snapthread
