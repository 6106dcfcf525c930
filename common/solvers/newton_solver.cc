#include "solvers/newton_solver.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace snapthread {

SolverBase::SolverBase(const Model& model, const SolverOptions& options)
    : model_(model), options_(options), n_(model.NumStates()) {
  h_ = model_.HessianPattern();
  h_mod_ = h_;
  std::string error;
  factor_ = MakeLinearSolver(options_.linear_solver, n_, model_.HessianBandwidth(), &error);
  alt_factor_ = MakeLinearSolver(options_.linear_solver, n_, model_.HessianBandwidth(), &error);
  if (!factor_ || !alt_factor_) throw std::invalid_argument("solver.linear_solver: " + error);
  if (factor_->Analyze(h_) != LinearSolverStatus::kSuccess ||
      alt_factor_->Analyze(h_) != LinearSolverStatus::kSuccess) {
    throw std::runtime_error("linear solver analysis failed: " + factor_->message());
  }
  diag_index_.assign(n_, -1);
  for (int j = 0; j < n_; ++j) {
    for (int p = h_.outerIndexPtr()[j]; p < h_.outerIndexPtr()[j + 1]; ++p) {
      if (h_.innerIndexPtr()[p] == j) diag_index_[j] = p;
    }
    if (diag_index_[j] < 0) throw std::logic_error("Hessian pattern lacks a diagonal entry");
  }
  eig_.Resize(n_);
  g_.resize(n_);
  dx_.resize(n_);
  trial_.resize(n_);
  last_good_.resize(n_);
  dx_scratch_.resize(n_);
}

void SolverBase::Reset() {
  eig_.Reset();
  factor_valid_ = false;
  lambda_ref_ = -1.0;
}

void SolverBase::Classify(SolverSummary* s) {
  const bool indefinite = s->negative_pivots != 0;
  const double ref = lambda_ref_ > 0.0 ? lambda_ref_ : s->lambda_min;
  const bool near_fold = indefinite || !(s->lambda_min > options_.degeneracy_ratio * ref);
  if (!near_fold && (s->IsConverged() || s->snapped)) lambda_ref_ = s->lambda_min;
  // kSnapped is decided by the caller from the jump of the state (EquilibriumTracker).
  s->status = near_fold ? EquilibriumStatus::kNearFold : EquilibriumStatus::kRegular;
}

int SolverBase::Budget() const {
  return options_.max_iterations > 0 ? options_.max_iterations : SolverOptions::kUnlimitedIterations;
}

void SolverBase::BeginSolve(SolverSummary* s) {
  *s = SolverSummary{};
  start_ = Clock::now();
  factor_valid_ = false;
  factor_before_tiny_step_ = false;
}

// A Newton step this small (model length units) changes E_xx by a relative O(1e-6):
// the factorisation at the state before it still serves K (error O(step)) and the
// inertia, and the update saves a Hessian assembly and factorisation — at n = 10 about a
// third of its cost. Near folds steps are far larger and the factor is always fresh.
constexpr double kReuseStep = 1e-6;

void SolverBase::TakeNewtonStep(Vec* x) {
  *x -= dx_;
  factor_before_tiny_step_ = dx_.lpNorm<Eigen::Infinity>() <= kReuseStep;
}

bool SolverBase::NextIteration(double r, Vec* x, SolverSummary* s) {
  if (!std::isfinite(r)) {
    *x = last_good_;
    s->termination = Termination::kNonFinite;
    s->message = "non-finite gradient; state restored";
    return false;
  }
  if (r < options_.cutoff) {
    s->termination = Termination::kConverged;
    return false;
  }
  if (!BudgetLeft(*s)) return false;
  // Stagnation: |E_x| has not halved for 20 iterations although it is within 1000x of
  // the cutoff — the cutoff is below the gradient's round-off (1e-10 on a long thread),
  // where an unlimited budget would otherwise spin for kUnlimitedIterations. Far from
  // the cutoff a globalised descent may legitimately crawl through a fold's bottleneck:
  // there only 200 iterations without halving stop it.
  if (s->iterations == 0 || r < 0.5 * best_residual_) {
    best_residual_ = r;
    stalled_iterations_ = 0;
  } else if (++stalled_iterations_ >= (r < 1e3 * options_.cutoff ? 20 : 200)) {
    s->message = "no progress in " + std::to_string(stalled_iterations_) +
                 " iterations (residual at round-off?)";
    return false;
  }
  ++s->iterations;
  last_good_ = *x;
  return true;
}

void SolverBase::Conclude(const Vec& u, Vec* x, SolverSummary* s, bool leave_saddles) {
  bool gradient_current = s->termination != Termination::kNonFinite;
  if (!x->allFinite()) {
    *x = last_good_;
    s->termination = Termination::kNonFinite;
    gradient_current = false;
  }
  Finish(*x, u, s, gradient_current);
  if (leave_saddles) LeaveSaddle(u, x, s);
  Classify(s);
}

bool SolverBase::BudgetLeft(const SolverSummary& s) const {
  if (s.iterations >= Budget()) return false;
  if (options_.max_time_us > 0.0) {
    const double us = std::chrono::duration<double, std::micro>(Clock::now() - start_).count();
    if (us >= options_.max_time_us) return false;
  }
  return true;
}

double SolverBase::EvalGradient(const Vec& x, const Vec& u, Vec* g, SolverSummary* s) const {
  model_.Gradient(x, u, g);
  ++s->gradient_evaluations;
  return g->norm();
}

LinearSolverStatus SolverBase::FactorAt(const Vec& x, const Vec& u, SolverSummary* s) {
  model_.Hessian(x, u, &h_);
  ++s->hessian_evaluations;
  ++s->factorizations;
  const LinearSolverStatus st = factor_->Factorize(h_);
  factor_valid_ = st == LinearSolverStatus::kSuccess;
  factor_before_tiny_step_ = false;
  return st;
}

LinearSolverStatus SolverBase::FactorShifted(double shift, SolverSummary* s) {
  std::copy(h_.valuePtr(), h_.valuePtr() + h_.nonZeros(), h_mod_.valuePtr());
  for (int i = 0; i < n_; ++i) h_mod_.valuePtr()[diag_index_[i]] += shift;
  ++s->factorizations;
  return alt_factor_->Factorize(h_mod_);
}

bool SolverBase::GlobalizedStep(const Vec& u, Vec* x, Vec* g, SolverSummary* s) {
  // Inertia-corrected Newton (Nocedal & Wright, Alg. 3.3): add tau I until the LDL^T
  // has no negative pivot, then backtrack on the energy (Armijo).
  const LinearSolverStatus st = FactorAt(*x, u, s);
  const SymmetricLinearSolver* f = factor_.get();
  if (st != LinearSolverStatus::kSuccess || factor_->NegativePivots() > 0) {
    double max_diag = 0.0;
    for (int i = 0; i < n_; ++i) max_diag = std::max(max_diag, std::abs(h_.valuePtr()[diag_index_[i]]));
    double tau = std::max(1e-3 * max_diag, 1e-8);
    if (st == LinearSolverStatus::kSuccess) {
      // Indefinite but factorised: shift by twice the most negative eigenvalue's size
      // (tracked by inverse iteration), so the step along that mode is as long as a
      // Newton step, not a creeping gradient step (escaping a symmetric saddle).
      const double lambda0 = eig_.Update(*factor_, h_, 4);
      if (lambda0 < 0.0) tau = std::max(2.0 * std::abs(lambda0), 1e-10 * max_diag);
    }
    bool ok = false;
    for (int k = 0; k < 60; ++k) {
      if (FactorShifted(tau, s) == LinearSolverStatus::kSuccess && alt_factor_->NegativePivots() == 0) {
        ok = true;
        break;
      }
      tau *= 4.0;
    }
    if (!ok) return false;
    f = alt_factor_.get();
  }
  if (f->Solve(*g, &dx_) != LinearSolverStatus::kSuccess) return false;
  dx_ = -dx_;
  const double e0 = model_.Energy(*x, u);
  const double slope = g->dot(dx_);
  if (!(slope < 0.0)) return false;
  // Near convergence the decrease falls below the round-off of E itself; there the
  // full step is accepted when it reduces |E_x| (a gradient-norm fallback).
  const double noise = 1e-13 * (1.0 + std::abs(e0));
  const double g0 = g->norm();
  double alpha = 1.0;
  for (int k = 0; k < 40; ++k) {
    trial_ = *x + alpha * dx_;
    const double e = model_.Energy(trial_, u);
    if (std::isfinite(e) && e <= e0 + 1e-4 * alpha * slope) {
      x->swap(trial_);
      return true;
    }
    if (std::isfinite(e) && std::abs(e - e0) <= noise) {
      model_.Gradient(trial_, u, &dx_scratch_);
      ++s->gradient_evaluations;
      if (dx_scratch_.norm() < g0) {
        x->swap(trial_);
        return true;
      }
    }
    alpha *= 0.5;
  }
  return false;
}

void SolverBase::Finish(const Vec& x, const Vec& u, SolverSummary* s, bool gradient_current) {
  s->residual = gradient_current ? g_.norm() : EvalGradient(x, u, &g_, s);
  s->energy = model_.Energy(x, u);
  // The factorisation at the returned state serves implicit differentiation (K) and
  // the eigenvalue estimate (or the one before a tiny last Newton step, kReuseStep).
  const LinearSolverStatus st =
      (factor_before_tiny_step_ && factor_valid_) ? LinearSolverStatus::kSuccess : FactorAt(x, u, s);
  factor_before_tiny_step_ = false;
  if (st == LinearSolverStatus::kSuccess) {
    s->negative_pivots = factor_->NegativePivots();
    // Two warm-started steps track the eigenpair; a cold start or a new branch needs more.
    s->lambda_min = eig_.Update(*factor_, h_, eig_.initialized() && !s->snapped ? 2 : 40);
  } else {
    s->negative_pivots = -1;
    s->lambda_min = 0.0;  // singular to working precision
  }
  s->solve_us = std::chrono::duration<double, std::micro>(Clock::now() - start_).count();
}

bool SolverBase::MinimizeFully(const Vec& u, Vec* x, SolverSummary* s) {
  constexpr int kMaxIterations = 400;  // the snap minimiser converges in ~10-20
  double r = EvalGradient(*x, u, &g_, s);
  for (int it = 0; it < kMaxIterations; ++it) {
    if (!std::isfinite(r)) return false;
    if (r < options_.cutoff) {
      // Stationary: a minimum only if E_xx has no negative pivot.
      if (FactorAt(*x, u, s) != LinearSolverStatus::kSuccess || factor_->NegativePivots() == 0) return true;
      eig_.Update(*factor_, h_, 8);
      const Vec& v = eig_.vector();
      const double e0 = model_.Energy(*x, u);
      // Along the negative mode E falls as lambda s^2 / 2 for small s, and may rise
      // again at once (a pitchfork's quartic): halve the step until E decreases.
      double step = 0.2 * options_.max_reduction_step / std::max(v.lpNorm<Eigen::Infinity>(), 1e-300);
      bool moved = false;
      for (int k = 0; k < 30 && !moved; ++k, step *= 0.5) {
        trial_ = *x + step * v;
        const double ep = model_.Energy(trial_, u);
        trial_ = *x - step * v;
        const double em = model_.Energy(trial_, u);
        if (std::min(ep, em) < e0) {
          *x += (ep < em ? step : -step) * v;
          moved = true;
        }
      }
      if (!moved) return true;  // flat to round-off: accept
      r = EvalGradient(*x, u, &g_, s);
      continue;
    }
    ++s->iterations;
    if (!GlobalizedStep(u, x, &g_, s)) {
      r = EvalGradient(*x, u, &g_, s);
      return r < 1e3 * options_.cutoff;
    }
    r = EvalGradient(*x, u, &g_, s);
  }
  return r < options_.cutoff;
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

NewtonSolver::NewtonSolver(const Model& model, const SolverOptions& options)
    : SolverBase(model, options) {}

SolverSummary NewtonSolver::Solve(const Vec& u, Vec* x) {
  SolverSummary s;
  BeginSolve(&s);
  const bool line_search = options_.method == Method::kNewtonLineSearch;
  last_good_ = *x;
  double r = EvalGradient(*x, u, &g_, &s);
  s.termination = Termination::kBudgetSpent;
  while (NextIteration(r, x, &s)) {
    if (line_search) {
      if (!GlobalizedStep(u, x, &g_, &s)) {
        s.termination = Termination::kLinearSolverFailed;
        s.message = "no descent step found";
        break;
      }
    } else {
      // (2.18): linearise the field E_x at x_i, solve for its zero.
      if (FactorAt(*x, u, &s) != LinearSolverStatus::kSuccess ||
          factor_->Solve(g_, &dx_) != LinearSolverStatus::kSuccess) {
        s.termination = Termination::kLinearSolverFailed;
        s.message = std::string("factorisation failed: ") + factor_->message();
        break;
      }
      TakeNewtonStep(x);
    }
    r = EvalGradient(*x, u, &g_, &s);
  }
  // Plain Newton (2.18) is kept as the seed's baseline: it may sit on a maximum or a
  // saddle (Fig 2.5). The globalised variant may not.
  Conclude(u, x, &s, line_search);
  return s;
}

}  // namespace snapthread
