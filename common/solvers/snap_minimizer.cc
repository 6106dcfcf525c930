// SolverBase's snap minimiser: globalised minimisation past the budget, leaving saddles
// along the negative mode or the symmetry orbits, and carrying a snap over updates.
#include "solvers/solver_base.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace snapthread {

bool SolverBase::ContinueSnap(const Vec& u, Vec* x, SolverSummary* s) {
  if (!snap_in_progress_) return false;
  s->snapped = true;
  s->termination = MinimizeFully(u, x, s) ? Termination::kConverged : Termination::kLinearSolverFailed;
  Conclude(u, x, s, /*leave_saddles=*/true);
  return true;
}

bool SolverBase::MinimizeFully(const Vec& u, Vec* x, SolverSummary* s) {
  constexpr int kMaxIterations = 400;  // the snap minimiser converges in ~10-20
  // A snap across a symmetry axis goes round the orbit: move there on the circle first.
  MoveAlongSymmetries(u, x);
  // |E_x| that has not halved for this many steps is asked whether it is at its
  // round-off (AtRoundOff): there the state is as stationary as double precision allows.
  constexpr int kStallSteps = 8;
  double r = EvalGradient(*x, u, s);
  double best = r;
  int stalls = 0;
  snap_in_progress_ = false;
  for (int it = 0; it < kMaxIterations; ++it) {
    if (!std::isfinite(r)) return false;
    if (r < 0.5 * best) {
      best = r;
      stalls = 0;
    } else {
      ++stalls;
    }
    const bool round_off = r >= options_.cutoff && stalls >= kStallSteps && AtRoundOff(r, *x, u, s);
    if (round_off) {
      s->at_round_off = true;
      stalls = 0;
    }
    // The time budget caps a snap too (DESIGN.md #4 finishes it inside its update only
    // without one): stop at an accepted state, carry on at the next update.
    if (it > 0 && r >= options_.cutoff && TimeSpent()) {
      snap_in_progress_ = true;
      return false;
    }
    // Stationary: a minimum only if E_xx has no negative pivot. With a force tolerance a
    // minimum whose force is not certified to it yet takes more (Newton) steps below,
    // unless |E_x| is at its round-off.
    const bool stationary = r < options_.cutoff || round_off;
    if (stationary && FactorAt(*x, u, s) != LinearSolverStatus::kSuccess) return true;
    const bool saddle = stationary && ws_.factor->NegativePivots() > 0;
    if (stationary && !saddle && (round_off || ForceCertified(*x, u))) return true;
    if (saddle) {
      // A saddle along a symmetry orbit: its minimum is on the circle, not on a line.
      if (MoveAlongSymmetries(u, x)) {
        r = EvalGradient(*x, u, s);
        continue;
      }
      UpdateEigenpair(8);
      const Vec& v = ws_.eig.vector();
      Vec& trial = ws_.trial;
      const double e0 = model_.Energy(*x, u);
      // Along the negative mode E falls as lambda s^2 / 2 for small s, and may rise
      // again at once (a pitchfork's quartic): halve the step until E decreases.
      double step = 0.2 * options_.max_reduction_step / std::max(v.lpNorm<Eigen::Infinity>(), 1e-300);
      bool moved = false;
      constexpr double kInf = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 30 && !moved; ++k, step *= 0.5) {
        // Either way only where no segment passes through another (self-contact CCD).
        ws_.dx_scratch = step * v;
        const bool plus_ok = MaxStepFraction(*x, ws_.dx_scratch, u) >= 1.0;
        trial = *x + ws_.dx_scratch;
        const double ep = plus_ok ? model_.Energy(trial, u) : kInf;
        ws_.dx_scratch = -ws_.dx_scratch;
        const bool minus_ok = MaxStepFraction(*x, ws_.dx_scratch, u) >= 1.0;
        trial = *x + ws_.dx_scratch;
        const double em = minus_ok ? model_.Energy(trial, u) : kInf;
        if (std::min(ep, em) < e0) {
          *x += (ep < em ? step : -step) * v;
          moved = true;
        }
      }
      if (!moved) return true;  // flat to round-off: accept
      r = EvalGradient(*x, u, s);
      continue;
    }
    ++s->iterations;
    if (!GlobalizedStep(u, x, s)) {
      r = EvalGradient(*x, u, s);
      if (r >= 1e3 * options_.cutoff && AtRoundOff(r, *x, u, s)) s->at_round_off = true;
      return r < 1e3 * options_.cutoff || s->at_round_off;
    }
    r = EvalGradient(*x, u, s);
  }
  if (r >= options_.cutoff && AtRoundOff(r, *x, u, s)) s->at_round_off = true;
  return r < options_.cutoff || s->at_round_off;
}

bool SolverBase::MoveAlongSymmetries(const Vec& u, Vec* x) {
  return !ws_.orbits->empty() && ws_.orbits->MoveDownhill(u, x);
}

void SolverBase::LeaveSaddle(const Vec& u, Vec* x, SolverSummary* s) {
  if (!s->IsConverged() || s->negative_pivots <= 0) return;
  s->snapped = true;
  if (!MinimizeFully(u, x, s)) {
    s->termination = Termination::kLinearSolverFailed;
    s->message = "could not leave a saddle point";
  }
  Finish(*x, u, s);
}

}  // namespace snapthread
