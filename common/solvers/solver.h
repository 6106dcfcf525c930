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

namespace snapthread {

enum class Termination {
  kConverged,           // ||E_x|| < cutoff
  kBudgetSpent,         // iteration or time budget spent first
  kLinearSolverFailed,  // factorisation failed and no fallback could proceed
  kNonFinite,           // a NaN/Inf appeared; the state was restored
};
const char* ToString(Termination t);

// What the equilibrium looks like to a user of the force: regular, near a fold
// (E_xx nearly singular: stiffness from the reduction), or the state just snapped.
enum class EquilibriumStatus { kRegular = 0, kNearFold = 1, kSnapped = 2 };
const char* ToString(EquilibriumStatus s);

struct SolverSummary {
  Termination termination = Termination::kBudgetSpent;
  EquilibriumStatus status = EquilibriumStatus::kRegular;
  int iterations = 0;
  int gradient_evaluations = 0;
  int hessian_evaluations = 0;
  int factorizations = 0;
  double residual = 0.0;     // ||E_x||_2 at the returned state
  double energy = 0.0;
  double lambda_min = 0.0;   // smallest eigenvalue estimate of E_xx at the returned state
  int negative_pivots = 0;   // inertia of E_xx at the returned state
  // higher-order: the reduction found that the followed minimum had vanished and the
  // snap minimiser ran (whether the state really changed branch is the tracker's call).
  bool snapped = false;
  bool used_reduction = false;  // higher-order: the one-direction reduction was used
  double solve_us = 0.0;
  std::string message;

  bool IsConverged() const { return termination == Termination::kConverged; }
  std::string BriefReport() const;
};

class EquilibriumSolver {
 public:
  virtual ~EquilibriumSolver() = default;
  virtual Method method() const = 0;
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

// Throws std::invalid_argument if !options.IsValid().
std::unique_ptr<EquilibriumSolver> MakeSolver(const Model& model, const SolverOptions& options);

}  // namespace snapthread
