#include "solvers/higher_order_solver.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace snapthread {
namespace {

// Step for the central differences of the analytic gradient along v' (|v'|_inf = 1 in
// model units): r = D^3E[v',v'] to O(h^2) with round-off ~ eps |E_x| / h^2.
constexpr double kDifferenceStep = 1e-2;
// In a flat valley the quartic's minimum counts as the followed one out to this many
// reduction caps (max_reduction_step) along v'; beyond, the minimum is gone.
constexpr double kFlatValleyReach = 4.0;
// A valley is flat when lambda_0 is below this fraction of E_xx's largest diagonal entry
// (a 1000-segment thread: ~1e-12); a stiffer E_xx with a long Newton step is past a fold.
constexpr double kFlatValleyRatio = 1e-6;
// Newton steps that stall at the gradient's round-off before a row whose force is not
// certified yet is called accuracy-limited.
constexpr int kRoundOffRetries = 2;

double QuarticSlope(const ReducedQuartic& q, double s) {
  return q.phi1 + s * (2.0 * q.phi2 + s * (3.0 * q.phi3 + s * 4.0 * q.phi4));
}
double QuarticCurvature(const ReducedQuartic& q, double s) {
  return 2.0 * q.phi2 + s * (6.0 * q.phi3 + s * 12.0 * q.phi4);
}

}  // namespace

bool FollowedMinimum(const ReducedQuartic& q, double cap, double* s_out) {
  // Downhill direction. At phi1 == 0 exactly the state is already stationary along v':
  // it is the followed minimum if phi2 > 0, else move to the side where the cubic has
  // its minimum (sign(phi3)).
  double dir;
  if (q.phi1 != 0.0) {
    dir = q.phi1 > 0.0 ? -1.0 : 1.0;
  } else if (q.phi2 > 0.0) {
    *s_out = 0.0;
    return true;
  } else {
    dir = q.phi3 >= 0.0 ? 1.0 : -1.0;
  }
  // Roots of 3 phi3 s^2 + 2 phi2 s + phi1, the cubic truncation's slope. The stable
  // form (q = -(b + sign(b) sqrt(disc))/2, roots q/a and c/q) keeps a near-zero root
  // exact even when the other is huge (DESIGN.md #3).
  const double a = 3.0 * q.phi3, b = 2.0 * q.phi2, c = q.phi1;
  double roots[2];
  int count = 0;
  const double scale = std::max({std::abs(a), std::abs(b), std::abs(c)});
  if (scale == 0.0) return false;
  if (std::abs(a) <= 1e-14 * scale) {
    if (b != 0.0) roots[count++] = -c / b;
  } else {
    const double disc = b * b - 4.0 * a * c;
    if (disc < 0.0) return false;  // no stationary point of the cubic: the minimum is gone
    const double sq = std::sqrt(disc);
    const double qq = -0.5 * (b + (b >= 0.0 ? sq : -sq));
    if (qq != 0.0) {
      roots[count++] = c / qq;
      roots[count++] = qq / a;
    } else {
      roots[count++] = 0.0;  // b == 0 and c == 0
    }
  }
  double best = 0.0;
  bool found = false;
  for (int i = 0; i < count; ++i) {
    const double r = roots[i];
    if (!std::isfinite(r) || r * dir < 0.0) continue;
    if (!found || std::abs(r) < std::abs(best)) {
      best = r;
      found = true;
    }
  }
  if (!found) return false;
  // A minimum of the cubic model has non-negative curvature there.
  if (2.0 * q.phi2 + 6.0 * q.phi3 * best < 0.0) return false;
  // Refine on the quartic (a few safeguarded Newton steps on phi').
  double s = best;
  for (int it = 0; it < 8; ++it) {
    const double curv = QuarticCurvature(q, s);
    if (!(curv > 0.0)) break;
    const double next = s - QuarticSlope(q, s) / curv;
    if (!std::isfinite(next) || next * dir < 0.0) break;
    if (std::abs(next - s) <= 1e-15 * std::max(1.0, std::abs(s))) {
      s = next;
      break;
    }
    s = next;
  }
  if (std::abs(s) > cap) {
    // A minimum far outside the range where the expansion was sampled is spurious
    // (DESIGN.md #3): step to the cap in the downhill direction instead.
    s = dir * cap;
  }
  *s_out = s;
  return true;
}

bool QuarticMinimumNearby(const ReducedQuartic& q, double cap, double reach, double* s_out) {
  if (!(q.phi4 > 0.0) || !(reach > 0.0)) return false;
  if (q.phi1 == 0.0) {
    *s_out = 0.0;
    return q.phi2 >= 0.0;
  }
  // phi' starts against the downhill direction and, with phi4 > 0, ends along it: the
  // first sign change on a doubling grid out to `reach`, then bisection to the root.
  const double dir = q.phi1 > 0.0 ? -1.0 : 1.0;
  double lo = 0.0, hi = 0.0;
  for (double t = reach / 64.0;; t = std::min(2.0 * t, reach)) {
    if (QuarticSlope(q, dir * t) * dir >= 0.0) {
      hi = t;
      break;
    }
    lo = t;
    if (t >= reach) return false;
  }
  for (int it = 0; it < 60 && hi - lo > 1e-14 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (QuarticSlope(q, dir * mid) * dir >= 0.0 ? hi : lo) = mid;
  }
  *s_out = dir * std::min(hi, cap);
  return true;
}

HigherOrderSolver::HigherOrderSolver(const Model& model, const SolverOptions& options)
    : SolverBase(model, options) {
  for (Vec* v : {&delta_, &vt_, &w_, &rhs_, &gp_, &gm_, &xs_, &g_trial_}) v->resize(num_states());
  col_k_rows_.reserve(64);
  col_k_pos_.reserve(64);
  row_k_pos_.reserve(64);
}

LinearSolverStatus HigherOrderSolver::FactorRestricted(int k, SolverSummary* s) {
  // H_{-k,-k} of (2.52): the same pattern with row and column k replaced by e_k, so the
  // symbolic analysis is shared and a solve returns vectors with component k equal to
  // the right-hand side's k-th entry.
  SparseMatrix& h_mod = ModifiedHessian();
  const int* outer = h_mod.outerIndexPtr();
  const int* inner = h_mod.innerIndexPtr();
  double* val = h_mod.valuePtr();
  for (int p = outer[k]; p < outer[k + 1]; ++p) {
    const int i = inner[p];
    val[p] = (i == k) ? 1.0 : 0.0;
    if (i == k) continue;
    // Entry (k, i) in column i (sorted inner indices).
    const int* b = inner + outer[i];
    const int* e = inner + outer[i + 1];
    const int* it = std::lower_bound(b, e, k);
    if (it != e && *it == k) val[it - inner] = 0.0;
  }
  return FactorModified(s);
}

HigherOrderSolver::StepResult HigherOrderSolver::ReductionStep(const Vec& u, Vec* x, bool flat_valley,
                                                               SolverSummary* s) {
  s->used_reduction = true;
  const Vec& v = LowestEigenvector();
  // Scale v so its largest-modulus component v_k = 1 (2.44).
  int k = 0;
  v.cwiseAbs().maxCoeff(&k);
  if (FactorRestricted(k, s) != LinearSolverStatus::kSuccess) return StepResult::kFailed;

  if (!ReductionDirections(k)) return StepResult::kFailed;
  // e0 before the differences: a model may keep the energy of the state it evaluated last.
  const double e0 = model().Energy(*x, u);
  ReducedQuartic q;
  if (!ReducedQuarticAt(u, *x, k, s, &q)) return StepResult::kFailed;

  double s_star = 0.0;
  // A flat valley's minimum held by the quartic term alone is still the followed one when
  // it is near: within a few caps (kFlatValleyReach), as far as the expansion is trusted.
  const double cap = options().max_reduction_step;
  if (!FollowedMinimum(q, cap, &s_star) &&
      !(flat_valley && QuarticMinimumNearby(q, cap, kFlatValleyReach * cap, &s_star)))
    return StepResult::kSnap;

  return BacktrackAlongCurve(u, x, s_star, e0);
}

bool HigherOrderSolver::ReductionDirections(int k) {
  // DESIGN.md #2: the graph tangent v' with v'_k = 1, H_{-k,-k} v'_{-k} = -H_{-k,k}.
  // It equals v at the fold and makes the correction exactly Newton on a quadratic.
  rhs_.setZero();
  {
    const SparseMatrix& hess = Hessian();
    const int* outer = hess.outerIndexPtr();
    const int* inner = hess.innerIndexPtr();
    const double* val = hess.valuePtr();
    for (int p = outer[k]; p < outer[k + 1]; ++p) rhs_[inner[p]] = -val[p];
  }
  rhs_[k] = 1.0;
  if (SolveModified(rhs_, &vt_) != LinearSolverStatus::kSuccess) return false;

  // Newton in the complement: delta with delta_k = 0 and (E_x + H delta)_{-k} = 0.
  const Vec& g = Gradient();
  rhs_ = -g;
  rhs_[k] = 0.0;
  if (SolveModified(rhs_, &delta_) != LinearSolverStatus::kSuccess) return false;
  return true;
}

bool HigherOrderSolver::ReducedQuarticAt(const Vec& u, const Vec& x, int k, SolverSummary* s, ReducedQuartic* q) {
  // r = D^3E[v', v'] by central differences of the analytic gradient (2.37), and
  // q = (g+ - g-)/2h = H v' + h^2/6 D^4E[v',v',v'] for the quartic coefficient.
  const Vec& g = Gradient();
  const double h = kDifferenceStep;
  xs_ = x + h * vt_;
  EvalGradient(xs_, u, &gp_, s);
  xs_ = x - h * vt_;
  EvalGradient(xs_, u, &gm_, s);
  // r into rhs_ (scratch), q into gp_.
  rhs_ = (gp_ - 2.0 * g + gm_) / (h * h);
  gp_ = (gp_ - gm_) / (2.0 * h);

  // Hv' has zero components off k by construction of v'; (Hv')_k = H_{k,:} v'.
  double hvv = 0.0;
  {
    const SparseMatrix& hess = Hessian();
    const int* outer = hess.outerIndexPtr();
    const int* inner = hess.innerIndexPtr();
    const double* val = hess.valuePtr();
    for (int p = outer[k]; p < outer[k + 1]; ++p) hvv += val[p] * vt_[inner[p]];
  }
  const double r_v = rhs_.dot(vt_);           // D^3E[v',v',v']
  const double d4 = 6.0 * (gp_.dot(vt_) - hvv) / (h * h);  // D^4E[v',v',v',v']

  // (2.52): H_{-k,-k} w_{-k} = -1/2 r_{-k}, w_k = 0.
  gm_ = -0.5 * rhs_;
  gm_[k] = 0.0;
  if (SolveModified(gm_, &w_) != LinearSolverStatus::kSuccess) return false;
  const double r_w = rhs_.dot(w_);            // D^3E[v',v',w]

  // (2.54-2.55) along c(s) = x + delta + s v' + s^2 w. With (Hv')_{-k} = 0, w_k = 0
  // and (E_x + H delta)_{-k} = 0 the cross terms collapse:
  //   phi1 = E_x.v'   phi2 = 1/2 v'^T H v'   phi3 = 1/6 D^3[v'^3] + v'^T H w = 1/6 D^3[v'^3]
  //   phi4 = 1/2 w^T H w + 1/2 D^3[v',v',w] + 1/24 D^4[v'^4] = 1/4 r.w + 1/24 D^4[v'^4]
  q->phi1 = g.dot(vt_);
  q->phi2 = 0.5 * hvv;
  q->phi3 = r_v / 6.0;
  q->phi4 = 0.25 * r_w + d4 / 24.0;
  return true;
}

HigherOrderSolver::StepResult HigherOrderSolver::BacktrackAlongCurve(const Vec& u, Vec* x, double s_star, double e0) {
  // Energy decrease (Armijo-type) on every higher-order step (DESIGN.md #4): backtrack
  // along the curve; a step that cannot decrease the energy is refused (e0 from before
  // the differences: a model may keep the energy of the state it evaluated last).
  double alpha = 1.0;
  for (int it = 0; it < 12; ++it) {
    const double ss = alpha * s_star;
    xs_ = *x + alpha * delta_ + ss * vt_ + (ss * ss) * w_;
    // Self-contact: the chord to the new state must not pass a segment through another
    // (CCD); a shorter step along the curve is tried instead.
    gm_ = xs_ - *x;
    if (MaxStepFraction(*x, gm_, u) < 1.0) {
      alpha *= 0.5;
      continue;
    }
    const double e = model().Energy(xs_, u);
    if (std::isfinite(e) && e <= e0 + 1e-14 * std::abs(e0)) {
      x->swap(xs_);
      return StepResult::kAccepted;
    }
    alpha *= 0.5;
  }
  return StepResult::kFailed;
}

bool HigherOrderSolver::FinishSnap(const Vec& u, Vec* x, SolverSummary* s) {
  s->snapped = true;
  return MinimizeFully(u, x, s);
}

void HigherOrderSolver::SnapAndStop(const Vec& u, Vec* x, SolverSummary* s, double* r) {
  if (!FinishSnap(u, x, s)) {
    s->termination = Termination::kLinearSolverFailed;
    s->message = "snap minimiser did not converge";
  }
  *r = EvalGradient(*x, u, s);
  // Converged on the same rule as every iteration (the cutoff ceiling and the certified
  // force error, Converged), or at the gradient's round-off; not on |E_x| < cutoff alone.
  if (s->termination != Termination::kLinearSolverFailed && (s->at_round_off || Converged(*r, *x, u, s)))
    s->termination = Termination::kConverged;
}

bool HigherOrderSolver::EnterFlatValley(const Vec& u, Vec* x, double lambda0, SolverSummary* s, double* r) {
  // A long Newton step from a gradient at its round-off is noise amplified along a flat
  // valley, not a fold crossed: the state has converged as far as it can.
  if (AtRoundOff(*r, *x, u, s)) {
    StopAtRoundOff(s);
    return false;
  }
  // E_xx positive definite (no inertia change: NearFold saw no negative pivot), flat
  // (lambda_0 below kFlatValleyRatio of its largest diagonal entry) and a Newton step
  // longer than the reduction's cap: a flat valley, along whose soft mode the quadratic
  // model overshoots. The reduction steps along it with the reduced quartic (2.54-2.55),
  // and tells whether its minimum is still near. A stiff E_xx with such a step has
  // carried the state over a fold: finish it as a snap.
  flat_lambda_ = kFlatValleyRatio * MaxHessianDiagonal();
  if (!(lambda0 <= flat_lambda_)) {
    SnapAndStop(u, x, s, r);
    return false;
  }
  s->flat_valley = true;
  return true;
}

double HigherOrderSolver::MaxHessianDiagonal() {
  const SparseMatrix& hess = Hessian();
  double m = 0.0;
  for (int j = 0; j < hess.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(hess, j); it; ++it)
      if (it.row() == j) m = std::max(m, std::abs(it.value()));
  return m;
}

void HigherOrderSolver::FinishFlatValley(const Vec& u, Vec* x, SolverSummary* s, double* r) {
  const bool done = MinimizeFully(u, x, s);
  *r = EvalGradient(*x, u, s);
  // The stopping rule of every iteration: the cutoff ceiling and the certified force
  // error (Converged), or |E_x| at its round-off.
  if (done && (Converged(*r, *x, u, s) || s->at_round_off)) s->termination = Termination::kConverged;
}

HigherOrderSolver::NewtonCheck HigherOrderSolver::CheckNewtonStep(const Vec& u, const Vec& x, double lambda0,
                                                                  SolverSummary* s, bool* trial_gradient) {
  // Regular: the Newton step (2.18).
  if (ComputeNewtonStep() != LinearSolverStatus::kSuccess) return NewtonCheck::kFailed;
  // A Newton step longer than the reduction's cap leaves the region where the
  // quadratic model holds: the control step has carried the state over a fold while
  // lambda_0 still looked regular (DESIGN.md's open case). Finish it as a snap.
  if (NewtonStep().lpNorm<Eigen::Infinity>() > options().max_reduction_step) return NewtonCheck::kSnap;
  // Approaching a fold (lambda_0 below its reference) a Newton step must also
  // lower the energy; one that raises it is aimed at the saddle that is about to
  // meet the followed minimum, so this iteration uses the reduction instead.
  const double ref = ReferenceLambda() > 0.0 ? ReferenceLambda() : lambda0;
  bool take_newton = true;
  *trial_gradient = false;
  if (lambda0 < 1.0 * ref) {
    // E at x first (a model may keep the energy of the state it evaluated last: the
    // pass that gave E_xx or E_x here), then E_x at the trial state, which the
    // iteration needs there if the step is taken, and E with it.
    const double e_here = model().Energy(x, u);
    xs_ = x - NewtonStep();
    EvalGradient(xs_, u, &g_trial_, s);
    take_newton = model().Energy(xs_, u) <= e_here;
    *trial_gradient = true;
  }
  return take_newton ? NewtonCheck::kTake : NewtonCheck::kRefused;
}

bool HigherOrderSolver::NewtonIteration(const Vec& u, Vec* x, bool trial_gradient, double* r, SolverSummary* s) {
  TakeNewtonStep(u, x);
  // Where E_xx is regular Newton converges quadratically; a step that does not
  // even halve |E_x| says the quadratic model has failed (a fold is close): the
  // next iteration uses the reduction. (The step goes to the trial state, unless a
  // collision bound shortened it: then its gradient is not the one there.)
  const double r_before = *r;
  const bool at_trial = trial_gradient && std::memcmp(x->data(), xs_.data(), sizeof(double) * x->size()) == 0;
  if (at_trial) {
    *r = AdoptGradient(&g_trial_);
  } else {
    // After a step that was not tiny E_xx is needed here next (the next iteration
    // or Finish()): one pass gives it with E_x.
    *r = LastStepTiny() ? EvalGradient(*x, u, s) : EvalGradientAndHessian(*x, u, s);
  }
  return !(*r < 0.5 * r_before);
}

bool HigherOrderSolver::ReductionIteration(const Vec& u, Vec* x, LinearSolverStatus st, bool flat_valley,
                                           int* reduction_stalls, double* r, SolverSummary* s) {
  // A factorisation that failed on an exactly singular E_xx still allows the
  // reduction: it needs only the restricted factor and the last eigenvector.
  const bool many_negative = st == LinearSolverStatus::kSuccess && HessianFactor().NegativePivots() > 1;
  StepResult res = StepResult::kFailed;
  if (!many_negative) {
    EnsureEigenvector();
    res = ReductionStep(u, x, flat_valley, s);
  }
  if (res == StepResult::kSnap || many_negative) {
    // At the gradient's round-off the reduced quartic is noise: no vanished minimum.
    if (!many_negative && AtRoundOff(*r, *x, u, s)) {
      StopAtRoundOff(s);
      return false;
    }
    SnapAndStop(u, x, s, r);
    return false;
  }
  if (res == StepResult::kFailed) {
    // The reduction could not decrease the energy: one globalised step instead. Where
    // none decreases it either and |E_x| is at its round-off, the state has converged.
    if (!GlobalizedStep(u, x, s)) {
      if (AtRoundOff(*r, *x, u, s)) {
        StopAtRoundOff(s);
        return false;
      }
      s->termination = Termination::kLinearSolverFailed;
      s->message = "no descent step found";
      return false;
    }
  }
  // On the quartic the reduction converges like Newton. Where the followed minimum
  // has just vanished its ghost still attracts the quartic model, and the steps
  // crawl through the bottleneck: two steps in a row that do not halve |E_x| mean
  // the minimum is gone — finish the snap now rather than over the next updates.
  // A reduction step that raises |E_x| (the energy fell, the force grew) says the
  // same at once.
  // E_xx is needed at the new state next (the next iteration, Finish() or the snap
  // minimiser's first step): one pass gives it with E_x.
  const double r_before = *r;
  *r = EvalGradientAndHessian(*x, u, s);
  *reduction_stalls = (*r < 0.5 * r_before) ? 0 : *reduction_stalls + 1;
  if (!flat_valley && (*reduction_stalls >= 2 || *r > r_before)) {
    // Stalled at the gradient's round-off is converged (no vanished minimum to leave).
    if (AtRoundOff(*r, *x, u, s)) {
      StopAtRoundOff(s);
      return false;
    }
    SnapAndStop(u, x, s, r);
    return false;
  }
  return true;
}

SolverSummary HigherOrderSolver::Solve(const Vec& u, Vec* x) {
  SolverSummary s;
  if (!BeginSolve(u, *x, &s) || ContinueSnap(u, x, &s)) return s;
  Vec& xr = *x;
  double r = EvalGradientAtStart(xr, u, &s);
  s.termination = Termination::kBudgetSpent;
  bool newton_stalled = false;
  bool trial_gradient = false;  // g_trial_ holds E_x at xs_ (the Newton trial state)
  int reduction_stalls = 0;
  bool in_flat_valley = false;  // the last iteration stepped along a flat valley
  int round_off_stalls = 0;     // Newton steps stalled at round-off with the force uncertified
  while (NextIteration(r, u, x, &s)) {
    const LinearSolverStatus st = FactorAt(xr, u, &s);
    bool degenerate = true, flat_valley = false;
    double lambda0 = 0.0;
    if (st == LinearSolverStatus::kSuccess) {
      lambda0 = UpdateEigenpair(1);
      // DESIGN.md #1: degeneracy against a reference lambda_0 (the test DecideStatus
      // applies to the returned state).
      degenerate = NearFold(lambda0, HessianFactor().NegativePivots(), ReferenceLambda(),
                            options().degeneracy_ratio) ||
                   newton_stalled;
    }
    if (!degenerate) {
      const NewtonCheck check = CheckNewtonStep(u, xr, lambda0, &s, &trial_gradient);
      if (check == NewtonCheck::kFailed) {
        s.termination = Termination::kLinearSolverFailed;
        break;
      }
      if (check == NewtonCheck::kSnap) {
        if (!EnterFlatValley(u, &xr, lambda0, &s, &r)) break;
        flat_valley = true;
      }
      degenerate = check != NewtonCheck::kTake;
    }
    if (!degenerate) {
      newton_stalled = NewtonIteration(u, &xr, trial_gradient, &r, &s);
      // A regular Newton step that does not halve |E_x| at its round-off: converged as
      // far as double precision allows (not a fold: the reduction would only wander).
      // In a flat valley round-off in E_x moves the Newton step far along the soft mode,
      // and one stalled step says little: where the force is not certified yet, a few
      // more Newton steps (kRoundOffRetries) before the row is called accuracy-limited.
      if (newton_stalled && AtRoundOff(r, xr, u, &s)) {
        if (Converged(r, xr, u, &s)) {
          s.termination = Termination::kConverged;
          break;
        }
        if (++round_off_stalls > kRoundOffRetries) {
          StopAtRoundOff(&s);
          break;
        }
        newton_stalled = false;
      }
      continue;
    }
    in_flat_valley = flat_valley;
    if (!ReductionIteration(u, &xr, st, flat_valley, &reduction_stalls, &r, &s)) break;
  }
  // A budget spent sliding along a flat valley (E_xx positive definite: no inertia
  // change, no snap) is finished in this update like a snap (DESIGN.md #4), without the
  // snap's label: the state is still on its branch.
  if (s.termination == Termination::kBudgetSpent && in_flat_valley) FinishFlatValley(u, x, &s, &r);
  // A budget spent on an indefinite E_xx finishes the snap in this update (Conclude).
  Conclude(u, x, &s, /*leave_saddles=*/true, /*finish_snap_on_spent_budget=*/true);
  // On a branch as flat as a flat valley (lambda_min below the flatness scale met there)
  // the state may slide far on it: the tracker then asks for the solve's own evidence.
  if (s.lambda_min > 0.0 && s.lambda_min <= flat_lambda_) s.flat_valley = true;
  return s;
}

}  // namespace snapthread
