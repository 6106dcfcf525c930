// What one solve reports (after Ceres' Solver::Summary), and the one function that
// decides an update's equilibrium status from it.
#pragma once

#include <string>

namespace snapthread {

enum class Termination {
  // ||E_x|| < cutoff and, with a force tolerance, the certified force error within it;
  // or ||E_x|| stalled at the gradient's round-off with the force error within it
  // (at_round_off): an equilibrium as exact as double precision allows.
  kConverged,
  kBudgetSpent,         // iteration or time budget spent first
  kLinearSolverFailed,  // factorisation failed and no fallback could proceed
  kNonFinite,           // a NaN/Inf appeared; the state was restored
  kInvalidInput,        // the state or the controls had the wrong size or were not finite
  // The time budget (SolverOptions::max_time_us) ran out inside a snap: the state is the
  // snap minimiser's last accepted (energy-decreasing) one, no equilibrium; the next
  // update carries the snap on.
  kSnapping,
  // ||E_x|| stalled at the gradient's round-off (at_round_off) with the certified force
  // error above the force tolerance: an equilibrium as exact as double precision allows in
  // a valley so flat that round-off caps the force's accuracy (docs/accuracy.md). Usable.
  kAccuracyLimited,
};
const char* ToString(Termination t);

// What the equilibrium looks like to a user of the force: regular, near a fold
// (E_xx nearly singular: stiffness from the reduction), or the state just snapped;
// snapping: no equilibrium yet, a snap spread over updates by the time budget is under
// way; failed: no usable state (the solve failed, or a residual or energy is NaN or
// infinite) — never a force model.
enum class EquilibriumStatus { kRegular = 0, kNearFold = 1, kSnapped = 2, kSnapping = 3, kFailed = 4 };
const char* ToString(EquilibriumStatus s);

struct SolverSummary {
  Termination termination = Termination::kBudgetSpent;
  EquilibriumStatus status = EquilibriumStatus::kRegular;  // set by DecideStatus only
  int iterations = 0;
  int gradient_evaluations = 0;
  int hessian_evaluations = 0;
  int factorizations = 0;
  double residual = 0.0;     // ||E_x||_2 at the returned state
  double energy = 0.0;
  double lambda_min = 0.0;   // smallest eigenvalue estimate of E_xx at the returned state
  // The reference lambda_0 (of the last regular converged state) the status was judged
  // against (DESIGN.md #1); <= 0 before the first regular state.
  double lambda_ref = -1.0;
  int negative_pivots = 0;   // inertia of E_xx at the returned state (-1: not factorised)
  // The solve saw it leave the followed minimum: the reduction found it vanished (higher-
  // order) or an E_xx with more negative pivots than at the last returned state (an
  // inertia change, GlobalizedStep); whether the state changed branch is the tracker's call.
  bool snapped = false;
  bool used_reduction = false;  // higher-order: the one-direction reduction was used
  bool flat_valley = false;     // higher-order: a step slid along a flat valley (no snap)
  double solve_us = 0.0;
  // Certified force error of the returned state, model force units, max norm over the
  // controls (docs/accuracy.md): the force change |E_ux E_xx^-1 E_x| of the Newton
  // correction (2.14-2.15, 2.18) with a margin; -1 where no factorisation allowed one.
  double force_error = -1.0;
  // The force tolerance the solve stopped on, model force units; 0: none (the cutoff alone).
  double force_target = 0.0;
  // ||E_x|| stalled at the gradient's round-off: no larger than round_off_floor, the
  // change of E_x when every coordinate of x moves by a few units in the last place.
  bool at_round_off = false;
  double round_off_floor = 0.0;
  std::string message;

  // An equilibrium to the requested accuracy or to round-off (kAccuracyLimited included).
  bool IsConverged() const {
    return termination == Termination::kConverged || termination == Termination::kAccuracyLimited;
  }
  // False when the returned state is no usable state (the linear solver failed, a NaN
  // appeared, the input was invalid, the residual or energy is not finite): its force
  // must not be rendered. A spent budget is usable: the state is the last accepted one;
  // so is a snap under way (kSnapping), though it is no equilibrium.
  bool IsSolutionUsable() const;
  std::string BriefReport() const;
};

// The degeneracy test of DESIGN.md #1: E_xx is near a fold when it is indefinite or not
// factorised (negative_pivots != 0) or its lowest eigenvalue is at most tau times the
// reference lambda_0 of the last regular state (lambda_ref <= 0: none yet, judge
// against lambda_min itself) — never against the largest diagonal entry (stretching
// sets the diagonal).
bool NearFold(double lambda_min, int negative_pivots, double lambda_ref, double degeneracy_ratio);

// The one decision of an update's equilibrium status. Every solver calls it on its
// summary at the end of a solve with left_branch = false (a solver cannot tell a change
// of branch); the tracker calls it again with left_branch = whether the state jumped to
// another branch, and everything downstream (sweep CSV, server messages) reads
// summary.status:
//   failed     !summary.IsSolutionUsable() (it outranks everything);
//   snapping   termination kSnapping (a snap under way: no branch to judge yet);
//   snapped    left_branch (it outranks a near-fold verdict at the new state);
//   near-fold  NearFold(summary.lambda_min, .negative_pivots, .lambda_ref, ratio);
//   regular    otherwise.
EquilibriumStatus DecideStatus(const SolverSummary& summary, double degeneracy_ratio, bool left_branch);

}  // namespace snapthread
