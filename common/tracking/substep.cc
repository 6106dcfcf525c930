// EquilibriumTracker's retry of an update whose solve reached no usable state (a snap
// the snap minimiser crawls through): the snap finished a little further along the
// path, and the new branch followed back to the update's controls in sub-steps
// (natural-parameter continuation in the grasp).
#include <algorithm>
#include <cmath>

#include "tracking/tracker.h"

namespace snapthread {
namespace {

// The control step is first cut into sub-steps of kFirstSubstep; a sub-step that
// reaches no equilibrium is halved, down to kMinSubstep of the whole step, where the
// retry gives up. A sub-step after a success doubles back up to the first length.
constexpr double kFirstSubstep = 0.25;
constexpr double kMinSubstep = 1.0 / 64;
// How far past the update's controls the retry looks, in control steps.
constexpr double kLookAhead[] = {1.0, 2.0, 4.0};

bool Unusable(const SolverSummary& s) {
  return s.termination == Termination::kLinearSolverFailed || s.termination == Termination::kNonFinite;
}

// The solve's work, added into `total` (the update reports everything it did).
void AddWork(const SolverSummary& s, SolverSummary* total) {
  total->iterations += s.iterations;
  total->gradient_evaluations += s.gradient_evaluations;
  total->hessian_evaluations += s.hessian_evaluations;
  total->factorizations += s.factorizations;
  total->solve_us += s.solve_us;
}

}  // namespace

bool EquilibriumTracker::ContinueInSubsteps(const Vec& u0, const Vec& u1, Vec* x, SolverSummary* total,
                                            SolverSummary* last) {
  double s = 0.0, ds = kFirstSubstep;
  Vec trial, us;
  bool snapped = false;
  while (s < 1.0) {
    const double next = std::min(1.0, s + ds);
    us = u0 + next * (u1 - u0);
    trial = *x;
    *last = solver_->Solve(us, &trial);
    AddWork(*last, total);
    if (last->IsConverged() && trial.allFinite()) {
      // An equilibrium at this sub-step: the lagged data (the rod's frames) follow it,
      // as they follow every accepted state of a path (the caller accepts the last).
      *x = trial;
      s = next;
      ++substeps_;
      snapped = snapped || last->snapped;
      if (s < 1.0 && history_ != nullptr) history_->AcceptState(*x, us);
      ds = std::min(2.0 * ds, kFirstSubstep);
    } else if ((ds *= 0.5) < kMinSubstep) {
      return false;
    }
  }
  last->snapped = last->snapped || snapped;
  return true;
}

bool EquilibriumTracker::RetryFailedUpdate(const Vec& u) {
  // Only a solve with no usable state (the snap minimiser stopped on its own cap, or a
  // linear solve failed) and no time budget: a budget is the user's limit on the
  // update, and a snap spread over updates (kSnapping) is carried on by the solver.
  const SolverSummary first = result_.summary;
  if (!Unusable(first) || options_.max_time_us > 0.0 || !u.allFinite() || !x_.allFinite()) return false;
  // Allocates: only on an update that failed, never on the device's budgeted loop.
  SolverSummary total = first, last;
  bool done = false;
  Vec x;
  // A snap the solver crawls through where the fold has only just been crossed (the old
  // branch's remnant, a saddle, holds it): further along the step, u + a (u - u_prev),
  // the remnant is gone and the snap finishes; the new branch is then followed back to u
  // in sub-steps.
  for (double a : kLookAhead) {
    if (done) break;
    const Vec ahead = u + a * (u - u_prev_);
    x = x_;
    last = solver_->Solve(ahead, &x);
    AddWork(last, &total);
    if (!last.IsConverged() || !x.allFinite()) continue;
    if (history_ != nullptr) history_->AcceptState(x, ahead);
    done = ContinueInSubsteps(ahead, u, &x, &total, &last);
  }
  if (!done) {
    // No equilibrium: back to the failed state, solved once more at u (with the lagged
    // data the retries moved) so the solver's factorisation is that state's; the update
    // reports failure as before unless this solve converges. No sub-steps to report.
    substeps_ = 0;
    x = x_;
    last = solver_->Solve(u, &x);
    AddWork(last, &total);
  }
  x_ = x;
  // The last solve's outcome with the work of all of them (the caller judges by the
  // jump whether the state left its branch).
  result_.summary = std::move(last);
  result_.summary.iterations = total.iterations;
  result_.summary.gradient_evaluations = total.gradient_evaluations;
  result_.summary.hessian_evaluations = total.hessian_evaluations;
  result_.summary.factorizations = total.factorizations;
  result_.summary.solve_us = total.solve_us;
  result_.summary.snapped = result_.summary.snapped || first.snapped;
  return done;
}

}  // namespace snapthread
