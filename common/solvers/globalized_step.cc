// SolverBase::GlobalizedStep: the inertia-corrected Newton direction and its Armijo line search.
#include "solvers/solver_base.h"

#include <algorithm>
#include <cmath>

namespace snapthread {

bool SolverBase::GlobalizedStep(const Vec& u, Vec* x, SolverSummary* s) {
  Workspace& w = ws_;
  const Vec* g = &w.g;
  // Inertia-corrected Newton (Nocedal & Wright, Alg. 3.3): add tau I until the LDL^T
  // has no negative pivot, then backtrack on the energy (Armijo).
  const LinearSolverStatus st = FactorAt(*x, u, s);
  const SymmetricLinearSolver* f = w.factor.get();
  // More negative pivots than at the last returned state: the inertia has changed, the
  // state is out of the followed minimum's basin (a fold crossed, or a saddle met).
  if (st == LinearSolverStatus::kSuccess && w.factor->NegativePivots() > accepted_negative_pivots_)
    s->snapped = true;
  if (st != LinearSolverStatus::kSuccess || w.factor->NegativePivots() > 0) {
    EnsureSparseHessian();
    double max_diag = 0.0;
    for (int i = 0; i < n_; ++i) max_diag = std::max(max_diag, std::abs(w.h.valuePtr()[w.diag_index[i]]));
    double tau = std::max(1e-3 * max_diag, 1e-8);
    if (st == LinearSolverStatus::kSuccess) {
      // Indefinite but factorised: shift by twice the most negative eigenvalue's size
      // (tracked by inverse iteration), so the step along that mode is as long as a
      // Newton step, not a creeping gradient step (escaping a symmetric saddle).
      const double lambda0 = UpdateEigenpair(4);
      if (lambda0 < 0.0) tau = std::max(2.0 * std::abs(lambda0), 1e-10 * max_diag);
    }
    bool ok = false;
    for (int k = 0; k < 60; ++k) {
      if (FactorShifted(tau, s) == LinearSolverStatus::kSuccess && w.alt_factor->NegativePivots() == 0) {
        ok = true;
        break;
      }
      tau *= 4.0;
    }
    if (!ok) return false;
    f = w.alt_factor.get();
  }
  Vec& dx = w.dx;
  if (f->Solve(*g, &dx) != LinearSolverStatus::kSuccess) return false;
  dx = -dx;
  const double e0 = model_.Energy(*x, u);
  const double slope = g->dot(dx);
  if (!(slope < 0.0)) return false;
  // Near convergence the decrease falls below the round-off of E itself; there the
  // full step is accepted when it reduces |E_x| (a gradient-norm fallback).
  const double noise = 1e-13 * (1.0 + std::abs(e0));
  const double g0 = g->norm();
  // The line search starts where the step stops crossing nothing (self-contact CCD).
  double alpha = MaxStepFraction(*x, dx, u);
  if (!(alpha > 0.0)) return false;
  for (int k = 0; k < 40; ++k) {
    w.trial = *x + alpha * dx;
    const double e = model_.Energy(w.trial, u);
    if (std::isfinite(e) && e <= e0 + 1e-4 * alpha * slope) {
      x->swap(w.trial);
      return true;
    }
    if (std::isfinite(e) && std::abs(e - e0) <= noise) {
      model_.Gradient(w.trial, u, &w.dx_scratch);
      ++s->gradient_evaluations;
      if (w.dx_scratch.norm() < g0) {
        x->swap(w.trial);
        return true;
      }
    }
    alpha *= 0.5;
  }
  return false;
}

}  // namespace snapthread
