#include "solvers/solver_base.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace snapthread {

SolverBase::SolverBase(const Model& model, const SolverOptions& options)
    : model_(model),
      contact_(model.contact()),
      band_assembly_(model.band_assembly()),
      options_(options),
      n_(model.NumStates()),
      force_target_(options.force_tolerance > 0.0
                        ? std::max(options.force_tolerance * model.ForceScale(),
                                   options.force_floor_n / options.newtons_per_model_force)
                        : 0.0) {
  if (n_ <= 0) throw std::invalid_argument("solver: the model has no state variables");
  Workspace& w = ws_;
  w.h = model_.HessianPattern();
  if (w.h.rows() != n_ || w.h.cols() != n_)
    throw std::invalid_argument("solver: the model's Hessian pattern is not NumStates() square");
  w.h_mod = w.h;
  std::string error;
  w.factor = MakeLinearSolver(options_.linear_solver, n_, model_.HessianBandwidth(), &error);
  w.alt_factor = MakeLinearSolver(options_.linear_solver, n_, model_.HessianBandwidth(), &error);
  if (!w.factor || !w.alt_factor) throw std::invalid_argument("solver.linear_solver: " + error);
  if (w.factor->Analyze(w.h) != LinearSolverStatus::kSuccess ||
      w.alt_factor->Analyze(w.h) != LinearSolverStatus::kSuccess) {
    throw std::runtime_error("linear solver analysis failed: " + w.factor->message());
  }
  w.diag_index.assign(n_, -1);
  for (int j = 0; j < n_; ++j) {
    for (int p = w.h.outerIndexPtr()[j]; p < w.h.outerIndexPtr()[j + 1]; ++p) {
      if (w.h.innerIndexPtr()[p] == j) w.diag_index[j] = p;
    }
    if (w.diag_index[j] < 0) throw std::logic_error("Hessian pattern lacks a diagonal entry");
  }
  pattern_version_ = model_.HessianPatternVersion();
  w.eig.Resize(n_);
  w.orbits = std::make_unique<SymmetryOrbits>(model_);
  for (Vec* v : {&w.g, &w.dx, &w.trial, &w.last_good, &w.dx_scratch, &w.h_state, &w.g_band, &w.factor_x,
                 &w.err_dx, &w.err_x, &w.err_state, &w.noise_x, &w.noise_g})
    v->resize(n_);
  const int m = model_.NumControls();
  for (Vec* v : {&w.h_u, &w.err_eu0, &w.err_eu1, &w.err_df}) v->resize(m);
  w.exu.resize(n_, m);
}

void SolverBase::Reset() {
  ws_.eig.Reset();
  snap_in_progress_ = false;
  factor_valid_ = false;
  factor_at_state_ = false;
  err_serial_ = -1;
  lambda_ref_ = -1.0;
  accepted_negative_pivots_ = 0;
}

const SymmetricLinearSolver* SolverBase::Factorization() const {
  return factor_valid_ ? ws_.factor.get() : nullptr;
}

int SolverBase::Budget() const {
  return options_.max_iterations > 0 ? options_.max_iterations : SolverOptions::kUnlimitedIterations;
}

bool SolverBase::BeginSolve(const Vec& u, const Vec& x, SolverSummary* s) {
  *s = SolverSummary{};
  start_ = Clock::now();
  factor_valid_ = false;
  factor_at_state_ = false;
  err_serial_ = -1;
  factor_before_tiny_step_ = false;
  // Lagged model data (AcceptState) may have changed E since the last solve.
  hessian_ready_ = false;
  band_ready_ = false;
  energy_ready_ = false;
  // Eigen checks sizes only with assertions on: a Release build must check here.
  const char* why = nullptr;
  if (x.size() != n_) why = "the state has the wrong size";
  else if (u.size() != model_.NumControls()) why = "the controls have the wrong size";
  else if (!x.allFinite()) why = "the warm start is not finite";
  else if (!u.allFinite()) why = "the controls are not finite";
  if (why != nullptr) {
    s->termination = Termination::kInvalidInput;
    s->message = why;
    s->negative_pivots = -1;
    return false;
  }
  ws_.last_good = x;
  return true;
}

// A Newton step this small (model length units) changes E_xx by a relative O(1e-6):
// the factorisation at the state before it still serves K (error O(step)) and the
// inertia, and the update saves a Hessian assembly and factorisation — at n = 10 about a
// third of its cost. Near folds steps are far larger and the factor is always fresh.
constexpr double kReuseStep = 1e-6;

void SolverBase::TakeNewtonStep(const Vec& u, Vec* x) {
  // Continuous collision detection (self-contact): a step that would carry one segment
  // through another is shortened to where every gap keeps a tenth of its size.
  ws_.dx_scratch = -ws_.dx;
  const double alpha = MaxStepFraction(*x, ws_.dx_scratch, u);
  if (alpha < 1.0) ws_.dx *= alpha;
  *x -= ws_.dx;
  factor_before_tiny_step_ = ws_.dx.lpNorm<Eigen::Infinity>() <= kReuseStep;
}

bool SolverBase::NextIteration(double r, const Vec& u, Vec* x, SolverSummary* s) {
  if (!std::isfinite(r)) {
    *x = ws_.last_good;
    s->termination = Termination::kNonFinite;
    s->message = "non-finite gradient; state restored";
    return false;
  }
  if (Converged(r, *x, u, s)) {
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
    // Stalled at the gradient's round-off: as converged as double precision allows.
    if (AtRoundOff(r, *x, u, s)) {
      StopAtRoundOff(s);
      return false;
    }
    s->message = "no progress in " + std::to_string(stalled_iterations_) +
                 " iterations (residual at round-off?)";
    return false;
  }
  ++s->iterations;
  ws_.last_good = *x;
  return true;
}

void SolverBase::Conclude(const Vec& u, Vec* x, SolverSummary* s, bool leave_saddles,
                          bool finish_snap_on_spent_budget) {
  bool gradient_current = s->termination != Termination::kNonFinite;
  if (!x->allFinite()) {
    *x = ws_.last_good;
    s->termination = Termination::kNonFinite;
    gradient_current = false;
  }
  Finish(*x, u, s, gradient_current);
  if (leave_saddles) LeaveSaddle(u, x, s);
  // The budget ran out on an indefinite E_xx: the state is past the fold, where the
  // followed minimum no longer exists. Finish the snap in this update (DESIGN.md #4)
  // instead of crawling over the next ones. (If a minimum is right there after all, the
  // minimiser simply converges to it: no jump, no snap.)
  if (finish_snap_on_spent_budget && s->termination == Termination::kBudgetSpent &&
      s->negative_pivots > 0) {
    s->snapped = true;
    if (MinimizeFully(u, x, s)) s->termination = Termination::kConverged;
    Finish(*x, u, s);
  }
  // The time budget ran out inside the snap minimiser (wherever it was started): the
  // state is its last accepted one; the next update carries the snap on (ContinueSnap).
  if (snap_in_progress_) {
    s->termination = Termination::kSnapping;
    s->message = "time budget spent inside a snap; it continues at the next update";
  }
  // Converged to round-off with the force still outside its tolerance: round-off caps
  // the accuracy here (a very flat valley), and the row says so.
  s->force_target = force_target_;
  if (s->termination == Termination::kConverged && s->at_round_off && force_target_ > 0.0 &&
      s->force_error > force_target_)
    s->termination = Termination::kAccuracyLimited;
  if (s->IsSolutionUsable() && s->negative_pivots >= 0) accepted_negative_pivots_ = s->negative_pivots;
  // The status against the reference of the last regular state, then the reference.
  s->lambda_ref = lambda_ref_;
  s->status = DecideStatus(*s, options_.degeneracy_ratio, /*left_branch=*/false);
  if (s->status == EquilibriumStatus::kRegular && (s->IsConverged() || s->snapped))
    lambda_ref_ = s->lambda_min;
}

bool SolverBase::BudgetLeft(const SolverSummary& s) const {
  // Every update takes at least one iteration, whatever the clock says (a budget below
  // one iteration, or a preempted thread, must not stall the state for good).
  return s.iterations < Budget() && (s.iterations == 0 || !TimeSpent());
}

bool SolverBase::TimeSpent() const {
  if (!(options_.max_time_us > 0.0)) return false;
  return std::chrono::duration<double, std::micro>(Clock::now() - start_).count() >= options_.max_time_us;
}

double SolverBase::EvalGradient(const Vec& x, const Vec& u, Vec* g, SolverSummary* s) const {
  model_.Gradient(x, u, g);
  ++s->gradient_evaluations;
  return g->norm();
}

double SolverBase::EvalGradient(const Vec& x, const Vec& u, SolverSummary* s) {
  return EvalGradient(x, u, &ws_.g, s);
}

double SolverBase::EvalGradientAndHessian(const Vec& x, const Vec& u, SolverSummary* s) {
  factor_valid_ = false;  // the band below is the factorisation's storage
  factor_at_state_ = false;
  ++factor_serial_;
  factor_before_tiny_step_ = false;
  // A banded factorisation lends its band: the model writes E_xx there, and FactorAt()
  // factorises it in place (no compressed matrix, no copy; the compressed one is made
  // only if a globalised or reduction step asks for it, EnsureSparseHessian()).
  int bandwidth = -1;
  double* band = ws_.factor->AssemblyBand(&bandwidth);
  if (band != nullptr && band_assembly_ != nullptr &&
      band_assembly_->EnergyGradientAndBandHessian(x, u, &ws_.g, band, bandwidth, &h_state_energy_)) {
    band_ready_ = true;
    sparse_stale_ = true;
  } else {
    h_state_energy_ = model_.EnergyGradientAndHessian(x, u, &ws_.g, &ws_.h);
    SyncPattern();
    hessian_ready_ = true;
  }
  ++s->gradient_evaluations;
  ws_.h_state = x;
  ws_.h_u = u;
  energy_ready_ = true;
  return ws_.g.norm();
}

bool SolverBase::AssembleBandAt(const Vec& x, const Vec& u) {
  int bandwidth = -1;
  double* band = ws_.factor->AssemblyBand(&bandwidth);
  double energy = 0.0;
  if (band == nullptr || band_assembly_ == nullptr ||
      !band_assembly_->EnergyGradientAndBandHessian(x, u, &ws_.g_band, band, bandwidth, &energy))
    return false;
  sparse_stale_ = true;
  ws_.h_state = x;
  ws_.h_u = u;
  h_state_energy_ = energy;
  energy_ready_ = true;
  return true;
}

bool SolverBase::AtHessianState(const Vec& x) const {
  return x.size() == ws_.h_state.size() &&
         std::memcmp(x.data(), ws_.h_state.data(), sizeof(double) * x.size()) == 0;
}

LinearSolverStatus SolverBase::FactorAt(const Vec& x, const Vec& u, SolverSummary* s) {
  // E_xx from EvalGradientAtStart at this very state (bit for bit) is not evaluated again;
  // it counts as this factorisation's evaluation.
  // A valid factorisation made at this very state (the convergence test's, Converged)
  // serves again: nothing has been written into it since.
  if (factor_valid_ && factor_at_state_ && x.size() == n_ &&
      std::memcmp(x.data(), ws_.factor_x.data(), sizeof(double) * n_) == 0) {
    factor_before_tiny_step_ = false;
    return LinearSolverStatus::kSuccess;
  }
  const bool at_start = (hessian_ready_ || band_ready_) && AtHessianState(x);
  const bool in_band = band_ready_ && at_start;
  const bool have_h = hessian_ready_ && at_start;
  hessian_ready_ = false;
  band_ready_ = false;
  ++s->hessian_evaluations;
  ++s->factorizations;
  LinearSolverStatus st;
  if (in_band) {
    st = ws_.factor->FactorizeAssembled();  // ws_.h stays stale (sparse_stale_)
  } else if (!have_h && AssembleBandAt(x, u)) {
    // Elsewhere too E_xx goes straight into the band when the model can (E and E_x come
    // with it, into scratch): no compressed matrix, no copy.
    st = ws_.factor->FactorizeAssembled();
  } else {
    if (!have_h) model_.Hessian(x, u, &ws_.h);
    SyncPattern();
    sparse_stale_ = false;
    st = ws_.factor->Factorize(ws_.h);
  }
  factor_valid_ = st == LinearSolverStatus::kSuccess;
  factor_at_state_ = factor_valid_;
  ++factor_serial_;
  if (factor_valid_) ws_.factor_x = x;
  factor_before_tiny_step_ = false;
  return st;
}

void SolverBase::EnsureSparseHessian() {
  if (!sparse_stale_) return;
  model_.Hessian(ws_.h_state, ws_.h_u, &ws_.h);
  SyncPattern();
  sparse_stale_ = false;
}

void SolverBase::SyncPattern() {
  // Self-contact changes E_xx's pattern now and then (model.h, models/contact_terms.h):
  // ws_.h has just been given the new structure; the second matrix, the diagonal's
  // positions and both symbolic analyses follow it. The factorisations are discarded.
  const int version = model_.HessianPatternVersion();
  if (version == pattern_version_) return;
  Workspace& w = ws_;
  const SparseMatrix& p = model_.HessianPattern();
  const auto same = [](const SparseMatrix& a, const SparseMatrix& b) {
    return a.nonZeros() == b.nonZeros() &&
           std::equal(a.outerIndexPtr(), a.outerIndexPtr() + a.cols() + 1, b.outerIndexPtr()) &&
           std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), b.innerIndexPtr());
  };
  if (!same(w.h, p)) return;  // ws_.h not evaluated since the change
  pattern_version_ = version;
  if (same(w.h, w.h_mod)) return;
  w.h_mod = w.h;
  for (int j = 0; j < n_; ++j) {
    w.diag_index[j] = -1;
    for (int q = w.h.outerIndexPtr()[j]; q < w.h.outerIndexPtr()[j + 1]; ++q) {
      if (w.h.innerIndexPtr()[q] == j) w.diag_index[j] = q;
    }
  }
  // A failed analysis leaves the factorisation unanalysed: Factorize() then reports it.
  // The second factorisation (shifted or restricted matrices, rare) is analysed when it
  // is next used (FactorModified).
  w.factor->Analyze(w.h);
  alt_stale_ = true;
  factor_valid_ = false;
  factor_at_state_ = false;
  ++factor_serial_;
  factor_before_tiny_step_ = false;
  ++pattern_changes_;
}

double SolverBase::UpdateEigenpair(int iterations) {
  if (ws_.eig.Iterate(*ws_.factor, n_, iterations)) return ws_.eig.value();
  EnsureSparseHessian();
  return ws_.eig.Update(*ws_.factor, ws_.h, 0);
}

SparseMatrix& SolverBase::ModifiedHessian() {
  EnsureSparseHessian();
  std::copy(ws_.h.valuePtr(), ws_.h.valuePtr() + ws_.h.nonZeros(), ws_.h_mod.valuePtr());
  return ws_.h_mod;
}

LinearSolverStatus SolverBase::FactorModified(SolverSummary* s) {
  ++s->factorizations;
  if (alt_stale_) {  // the pattern changed since its analysis (SyncPattern)
    ws_.alt_factor->Analyze(ws_.h_mod);
    alt_stale_ = false;
  }
  return ws_.alt_factor->Factorize(ws_.h_mod);
}

LinearSolverStatus SolverBase::FactorShifted(double shift, SolverSummary* s) {
  double* val = ModifiedHessian().valuePtr();
  for (int i = 0; i < n_; ++i) val[ws_.diag_index[i]] += shift;
  return FactorModified(s);
}

void SolverBase::Finish(const Vec& x, const Vec& u, SolverSummary* s, bool gradient_current) {
  s->residual = gradient_current ? ws_.g.norm() : EvalGradient(x, u, s);
  // The warm start's energy came with its gradient and E_xx (EvalGradientAtStart).
  s->energy = energy_ready_ && AtHessianState(x) ? h_state_energy_ : model_.Energy(x, u);
  // The factorisation at the returned state serves implicit differentiation (K) and
  // the eigenvalue estimate (or the one before a tiny last Newton step, kReuseStep).
  const LinearSolverStatus st =
      (factor_before_tiny_step_ && factor_valid_) ? LinearSolverStatus::kSuccess : FactorAt(x, u, s);
  factor_before_tiny_step_ = false;
  if (st == LinearSolverStatus::kSuccess) {
    s->negative_pivots = ws_.factor->NegativePivots();
    // The certified force error of the returned state (docs/accuracy.md).
    s->force_error = ForceErrorFromFactor(x, u);
    // One warm-started step per update tracks the eigenpair (the vector converges over
    // the updates, and every iteration of the higher-order loop adds a step near a fold);
    // a cold start or a new branch needs more.
    s->lambda_min = UpdateEigenpair(ws_.eig.initialized() && !s->snapped ? 1 : 40);
  } else {
    s->negative_pivots = -1;
    s->lambda_min = 0.0;  // singular to working precision
    s->force_error = -1.0;
  }
  s->solve_us = std::chrono::duration<double, std::micro>(Clock::now() - start_).count();
}

}  // namespace snapthread
