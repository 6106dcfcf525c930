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
  // runs 1e-10) and, with a force tolerance, the grasp force is certified to it.
  double cutoff = 1e-6;
  // Stop in the units that matter (docs/accuracy.md): a solve converges only when its
  // certified force error (SolverSummary::force_error) is at most
  // max(force_tolerance * model.ForceScale(), force_floor_n / newtons_per_model_force).
  // 0 = the cutoff alone (an explicit --cutoff sets it so: the cutoff keeps its meaning).
  double force_tolerance = 1e-4;
  // Absolute floor of that tolerance in newtons at the device (scene key
  // solver.force_floor_n; 0 = none: every target is relative to the force scale).
  double force_floor_n = 0.0;
  // The scene's device.newtons_per_model_force (MakeTracker sets it), for force_floor_n.
  double newtons_per_model_force = 1.0;
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
