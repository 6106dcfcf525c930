// Solver options: which method, when to stop, which linear algebra. A plain struct with
// no dependency on the solvers themselves, so a scene can carry it (and the device client,
// which reads scenes, never links a solver).
#pragma once

#include <string>

namespace snapthread {

struct SolverOptions {
  // A registered solver's name (solvers/registry.h: "newton", "newton-ls",
  // "higher-order"). A name, not an enum, so this struct needs no solver code.
  std::string method = "higher-order";
  // Stop when the internal force ||E_x||_2 < cutoff (the seed uses 1e-6, its reference
  // runs 1e-10).
  double cutoff = 1e-6;
  // Iteration budget per control update; 0 means unlimited (capped at
  // kUnlimitedIterations as a safety net).
  int max_iterations = 50;
  // Wall-clock budget per update in microseconds; 0 = none (scene key
  // solver.time_budget_us, --time-budget-us). It caps a snap too: an update that runs out
  // inside one returns its last accepted state as kSnapping and the next update carries
  // the snap on (docs/time-budget.md). Checked once per iteration (a steady_clock read).
  double max_time_us = 0.0;
  // Linear algebra backend (see MakeLinearSolver).
  std::string linear_solver = "auto";
  // higher-order: degeneracy threshold tau on lambda_0 / lambda_0,ref (DESIGN.md #1).
  double degeneracy_ratio = 0.1;
  // higher-order: |s*| cap in model units (DESIGN.md #3).
  double max_reduction_step = 0.5;
  // Predictor for the warm start (DESIGN.md #5), used by the tracker: the tangent
  // -E_xx^-1 E_xu du where the last state was regular, else the secant 2 x_{i-1} - x_{i-2}.
  bool secant_predictor = true;

  static constexpr int kUnlimitedIterations = 10000;
  // Checks the numbers; the method and linear_solver names are checked where the solver
  // is made (MakeSolver), which knows the registered implementations.
  bool IsValid(std::string* error) const;
};

}  // namespace snapthread
