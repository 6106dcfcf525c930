// Equilibrium solvers behind one interface (Ceres-style Options + Summary).
//
//  newton        the seed's plain Newton (2.18): solve E_xx d = -E_x, no line search.
//  newton-ls     Newton with an inertia-corrected Hessian and Armijo backtracking.
//  higher-order  the seed's bifurcation-aware method (§2.3.5, §2.4): Newton where E_xx
//                is regular, the one-direction 4th-order reduction near folds and cusps.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "linalg/linear_solver.h"
#include "models/model.h"
#include "solvers/options.h"
#include "solvers/summary.h"

namespace snapthread {

class EquilibriumSolver {
 public:
  virtual ~EquilibriumSolver() = default;
  // The registered name (SolverOptions::method) this solver was made under.
  virtual const std::string& method() const = 0;
  // Moves *x (the warm start) to an equilibrium of E(., u). x keeps the last accepted
  // state on failure; it never holds NaN on return.
  virtual SolverSummary Solve(const Vec& u, Vec* x) = 0;
  // Forget tracked data (reference eigenvalue, eigenvector warm start).
  virtual void Reset() = 0;
  // The factorisation of E_xx at the returned state (for implicit differentiation);
  // null if the last Solve could not factorise it.
  virtual const SymmetricLinearSolver* Factorization() const = 0;
  // Unit eigenvector estimate of E_xx's smallest eigenvalue (summary.lambda_min) at the
  // returned state, tracked by inverse iteration with the factorisation.
  virtual const Vec& LowestEigenvector() const = 0;
};

// Makes the registered solver options.method (solvers/registry.h). Throws
// std::invalid_argument naming the field if !options.IsValid(), or if the method or the
// linear solver is not registered (listing the registered names).
std::unique_ptr<EquilibriumSolver> MakeSolver(const Model& model, const SolverOptions& options);

}  // namespace snapthread
