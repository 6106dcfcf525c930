#include "tracking/tracker.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace snapthread {
namespace {

// A start the path can begin from: converged, and a minimum (E_xx positive definite).
bool IsStableStart(const SolverSummary& s) { return s.IsConverged() && s.negative_pivots == 0; }

}  // namespace

EquilibriumTracker::EquilibriumTracker(std::unique_ptr<Model> model, const SolverOptions& options)
    : model_(std::move(model)),
      history_(model_ ? model_->history() : nullptr),
      contact_(model_ ? model_->contact() : nullptr),
      options_(options) {
  if (!model_) throw std::invalid_argument("EquilibriumTracker: null model");
  solver_ = MakeSolver(*model_, options_);
  const int n = model_->NumStates(), m = model_->NumControls();
  x_ = Vec::Zero(n);
  x_prev_ = x_;
  x_pred_ = x_;
  snap_origin_ = x_;
  u_ = Vec::Zero(m);
  u_prev_ = u_;
  eu_.resize(m);
  scratch_.resize(n);
  exu_.resize(n, m);
  euu_.resize(m, m);
  sol_.resize(n, m);
  quad_.resize(m, m);
  vexu_.resize(m);
  rhs_.resize(n);
  du_.resize(m);
  result_.force = Vec::Zero(m);
  result_.stiffness = Mat::Zero(m, m);
}

void EquilibriumTracker::SetOptions(const SolverOptions& options) {
  // The predictor's tangent lives in the old solver's factorisation: keep it as the full
  // columns E_xx^-1 E_xu before that solver goes.
  if (have_tangent_ && !tangent_in_sol_) {
    const SymmetricLinearSolver* f = solver_->Factorization();
    tangent_in_sol_ = f != nullptr && f->SolveMany(exu_, &sol_) == LinearSolverStatus::kSuccess && sol_.allFinite();
    have_tangent_ = tangent_in_sol_;
  }
  options_ = options;
  solver_ = MakeSolver(*model_, options_);
  have_prev_ = false;
}

const TrackResult& EquilibriumTracker::Reset(const Vec& u) {
  if (u.size() != model_->NumControls())
    throw std::invalid_argument("EquilibriumTracker::Reset: control size mismatch");
  solver_->Reset();
  ResetModelHistory();
  x_ = model_->InitialState(u);
  u_ = u;
  result_.summary = SolveStart(*model_, u, &x_);
  SolveAndStartHere();
  // Judged after the tracking solver's own solve, which may still leave a saddle.
  start_continuation_steps_ = 0;
  substeps_ = 0;
  if (start_family_ && !IsStableStart(result_.summary) && StartByContinuation(u)) {
    solver_->Reset();
    SolveAndStartHere();
  }
  return result_;
}

SolverSummary EquilibriumTracker::SolveStart(const Model& model, const Vec& u, Vec* x) const {
  // A reset must start on an equilibrium: unlimited, globalised solve.
  SolverOptions strict = options_;
  strict.max_iterations = 0;
  strict.max_time_us = 0.0;
  strict.method = "newton-ls";
  auto start_solver = MakeSolver(model, strict);
  SolverSummary s = start_solver->Solve(u, x);
  // The globalised solve can still stop on a saddle when the start is symmetric (a
  // straight compressed thread): leave along the negative mode until the inertia says
  // it is a minimum (no negative pivot).
  for (int k = 0; k < 8 && s.negative_pivots > 0; ++k) {
    const Vec& v = start_solver->LowestEigenvector();
    if (v.size() != x->size()) break;
    *x += (0.1 * snap_threshold_ / std::max(v.lpNorm<Eigen::Infinity>(), 1e-300)) * v;
    s = start_solver->Solve(u, x);
  }
  return s;
}

bool EquilibriumTracker::StartByContinuation(const Vec& u) {
  // Steps in t: at most kStep (doubled back up after a success), halved on a failure
  // down to kMinStep, where the continuation gives up.
  constexpr double kStep = 0.1, kMinStep = 1.0 / 1024;
  std::vector<Vec> accepted;  // the equilibria along t: the lagged data follow them
  Vec x = model_->InitialState(u), trial;
  SolverSummary s;
  double t = 0.0, dt = kStep;
  int steps = 0;
  for (bool first = true; first || t < 1.0;) {
    const double next = first ? 0.0 : std::min(1.0, t + dt);
    std::unique_ptr<Model> member = next < 1.0 ? start_family_(next) : nullptr;
    Model& m = member ? *member : *model_;
    if (HistoryCapability* h = m.history(); h != nullptr) {
      h->ResetHistory();
      for (const Vec& xa : accepted) h->AcceptState(xa, u);
    }
    trial = x;
    s = SolveStart(m, u, &trial);
    ++steps;
    if (IsStableStart(s)) {
      x = trial;
      t = next;
      first = false;
      accepted.push_back(x);
      dt = std::min(2.0 * dt, kStep);
    } else if (first || (dt *= 0.5) < kMinStep) {
      // Back to the direct start's lagged data (x_ is still its state).
      ResetModelHistory();
      AcceptModelState();
      return false;
    }
  }
  // The last step solved the tracker's own model with its lagged data at the state
  // before; SolveAndStartHere moves them to x.
  x_ = x;
  start_continuation_steps_ = steps;
  return true;
}

const TrackResult& EquilibriumTracker::SolveAndStartHere() {
  // Solve with the tracking solver so its factorisation and eigenpair are current.
  result_.summary = solver_->Solve(u_, &x_);
  result_.snapped = false;
  have_prev_ = false;
  have_tangent_ = false;
  x_prev_ = x_;
  u_prev_ = u_;
  ComputeForces();
  // After the force and K of this state (they use its factorisation): models with lagged
  // data (the rod's reference frames) move it to the accepted state.
  AcceptModelState();
  return result_;
}

const TrackResult& EquilibriumTracker::Resume(const Vec& x, const Vec& u) {
  if (u.size() != model_->NumControls() || x.size() != model_->NumStates())
    throw std::invalid_argument("EquilibriumTracker::Resume: state or control size mismatch");
  if (!x.allFinite() || !u.allFinite())
    throw std::invalid_argument("EquilibriumTracker::Resume: non-finite state or controls");
  solver_->Reset();
  ResetModelHistory();
  x_ = x;
  u_ = u;
  // Lagged data (the rod's reference frames) from the model's start to the saved state,
  // so E(x, u) is the energy the state was accepted under.
  AcceptModelState();
  return SolveAndStartHere();
}

void EquilibriumTracker::RelabelControls(const Vec& u) {
  if (u.size() != model_->NumControls() || !u.allFinite())
    throw std::invalid_argument("EquilibriumTracker::RelabelControls: bad controls");
  u_ = u;
  u_prev_ = u;
  have_prev_ = false;
  have_tangent_ = false;
}

const TrackResult& EquilibriumTracker::Update(const Vec& u) {
  if (u.size() != model_->NumControls())
    throw std::invalid_argument("EquilibriumTracker::Update: control size mismatch");
  // Warm start (DESIGN.md #5). Where the last state was regular, the tangent
  // dx/du = -E_xx^-1 E_xu from its implicit differentiation (TangentPrediction, with
  // the factorisation that gave K) is the better predictor: exact to first order without history, and unaffected
  // by a budget-limited previous update or by the grasp turning round. Near a fold
  // (the floored eigenvalue makes the tangent arbitrary) fall back to the secant
  // 2 x_{i-1} - x_{i-2}, scaled by how much of the previous control step the new one
  // repeats (the secant is reset by a snap; the tangent at the new branch is valid).
  x_pred_ = x_;
  // A snap cut by the time budget goes on from its last state: no prediction from a
  // state that is no equilibrium (neither the tangent nor the secant is kept for it).
  const bool continuing_snap = result_.summary.termination == Termination::kSnapping;
  const bool tangent_ok = have_tangent_ && !result_.stiffness_regularized &&
                          result_.summary.status != EquilibriumStatus::kNearFold;
  const bool predicted = options_.secant_predictor && tangent_ok && TangentPrediction(u);
  if (!predicted && options_.secant_predictor && have_prev_) {
    const double d2 = (u_ - u_prev_).squaredNorm();
    if (d2 > 0.0) {
      const double a = std::clamp((u - u_).dot(u_ - u_prev_) / d2, 0.0, 2.0);
      x_pred_ += a * (x_ - x_prev_);
    }
  }
  LimitPrediction(u);
  x_prev_ = x_;
  u_prev_ = u_;
  x_ = x_pred_;
  u_ = u;
  result_.summary = solver_->Solve(u, &x_);
  substeps_ = 0;
  FinishUnfinishedSnap(u);
  RetryFailedUpdate(u);
  // A snap is a jump to another branch: the state left the predicted one by more than
  // the threshold, unless the solve slid along a flat valley on its branch and saw no
  // sign of leaving it (summary.snapped: an inertia change, or the followed minimum
  // gone). The status is DecideStatus's, now with that fact. A snap spread over updates
  // jumps from the state predicted where it began.
  if (!continuing_snap) snap_origin_ = x_pred_;
  const double jump = (x_ - snap_origin_).lpNorm<Eigen::Infinity>();
  const bool slid = result_.summary.flat_valley && !result_.summary.snapped;
  const bool left_branch = jump > snap_threshold_ && !slid;
  result_.summary.status = DecideStatus(result_.summary, options_.degeneracy_ratio, left_branch);
  result_.snapped = result_.summary.status == EquilibriumStatus::kSnapped;
  // After a snap the secant would point along the jump: restart it (and during one).
  have_prev_ = !result_.snapped && result_.summary.status != EquilibriumStatus::kSnapping;
  ComputeForces();
  AcceptModelState();
  return result_;
}

void EquilibriumTracker::FinishUnfinishedSnap(const Vec& u) {
  constexpr int kSnapRetries = 10;
  // Far above the cutoff: a snap under way, not a solve stagnating at round-off just
  // above an absolute cutoff (which more iterations would not help).
  const double unfinished = 1e3 * options_.cutoff;
  for (int k = 0; k < kSnapRetries; ++k) {
    const SolverSummary& s = result_.summary;
    if (!s.snapped || s.termination != Termination::kLinearSolverFailed || options_.max_time_us > 0.0 ||
        !(s.residual > unfinished && std::isfinite(s.residual)) || !x_.allFinite())
      return;
    SolverSummary more = solver_->Solve(u, &x_);
    more.iterations += s.iterations;
    more.gradient_evaluations += s.gradient_evaluations;
    more.hessian_evaluations += s.hessian_evaluations;
    more.factorizations += s.factorizations;
    more.solve_us += s.solve_us;
    more.snapped = true;
    result_.summary = std::move(more);
  }
}

void EquilibriumTracker::ResetModelHistory() {
  if (history_ != nullptr) history_->ResetHistory();
}

void EquilibriumTracker::AcceptModelState() {
  if (history_ != nullptr) history_->AcceptState(x_, u_);
}

bool EquilibriumTracker::TangentPrediction(const Vec& u) {
  // dx = E_xx^-1 E_xu du: one solve with the factorisation of the last update's state
  // (still the solver's until this update's Solve), of a right-hand side that is
  // non-zero on the last nodes only. (The three columns E_xx^-1 E_xu themselves are
  // kept only across a change of solver, SetOptions.)
  du_ = u - u_;
  if (tangent_in_sol_) {
    scratch_.noalias() = sol_ * du_;
  } else {
    const SymmetricLinearSolver* f = solver_->Factorization();
    if (f == nullptr) return false;
    rhs_.noalias() = exu_ * du_;
    if (f->Solve(rhs_, &scratch_) != LinearSolverStatus::kSuccess) return false;
  }
  if (!scratch_.allFinite()) return false;
  const double step = scratch_.lpNorm<Eigen::Infinity>();
  // The cap keeps a wild tangent from throwing the warm start far; it grows with the
  // control step past hand speed (kHandSpeedStep), where the tangent's step grows with
  // it: cut to a fixed length, the prediction leaves the grasp's segment compressed by
  // most of the control step (an indefinite E_xx at the warm start, taken for a fold).
  constexpr double kHandSpeedStep = 0.01;
  const double cap = 5.0 * snap_threshold_ * std::max(1.0, du_.lpNorm<Eigen::Infinity>() / kHandSpeedStep);
  x_pred_ -= (step > cap ? cap / step : 1.0) * scratch_;
  return true;
}

void EquilibriumTracker::LimitPrediction(const Vec& u) {
  // Self-contact (CCD): the prediction moves the nodes from the accepted state at the
  // old controls to x_pred_ at the new ones; it must not carry a segment through another.
  // Shorten the predicted change of the state (to none at all, where only the grasp
  // moves) until it does not.
  if (contact_ == nullptr || contact_->MaxMotionFraction(x_, u_, x_pred_, u) >= 1.0) return;
  scratch_ = x_pred_ - x_;
  for (int k = 1; k <= 4; ++k) {
    x_pred_ = x_ + std::ldexp(1.0, -k) * scratch_;
    if (contact_->MaxMotionFraction(x_, u_, x_pred_, u) >= 1.0) return;
  }
  x_pred_ = x_;
}

void EquilibriumTracker::ComputeForces() {
  const Model& m = *model_;
  // F = -E_u at the equilibrium (envelope theorem, §2.3.4); at a degenerate point this
  // is still the finite, continuous force of (2.16-2.17).
  m.ControlDerivatives(x_, u_, &eu_, &exu_, &euu_);
  result_.force = -eu_;
  result_.energy = result_.summary.energy;
  result_.probe = m.Probe(x_, u_);

  // K = dF/du = -(E_uu - E_ux E_xx^-1 E_xu) (implicit differentiation, (2.14-2.15)).
  result_.stiffness_regularized = false;
  if (result_.summary.status == EquilibriumStatus::kSnapping) {
    // Mid-snap (time budget): the state is an accepted, energy-decreasing one but no
    // equilibrium, so there is no implicit derivative. The force of that state with
    // K = 0: the device renders a constant force that moves on towards the new branch
    // update by update, never a stiffness extrapolated from a non-equilibrium.
    result_.stiffness.setZero();
    result_.stiffness_regularized = true;
    have_tangent_ = false;
    return;
  }
  // E_ux E_xx^-1 E_xu from the factorisation the solver returned: (L^-1 E_xu)^T D^-1
  // (L^-1 E_xu), the forward sweeps alone, where E_xu is non-zero (the grasp's nodes).
  const SymmetricLinearSolver* f = solver_->Factorization();
  const bool ok = f != nullptr && f->InverseQuadraticForm(exu_, &quad_) == LinearSolverStatus::kSuccess &&
                  quad_.allFinite();
  const double lambda0 = result_.summary.lambda_min;
  const bool regular_state = ok && result_.summary.negative_pivots == 0 &&
                             result_.summary.status == EquilibriumStatus::kRegular;
  if (regular_state) lambda_ref_ = lambda0;
  if (ok && !regular_state && result_.summary.negative_pivots <= 1) {
    // Near a fold E_xx^-1 blows up along its lowest mode v: floor that one eigenvalue
    // at tau * lambda_ref (the spectral term v v^T / lambda_0 becomes v v^T / floor),
    // so K is finite and continuous while the rest of the response is exact: the term
    // adds (1/floor - 1/lambda_0) (E_ux v)(E_ux v)^T.
    const Vec& v = solver_->LowestEigenvector();
    const double floor = std::max(options_.degeneracy_ratio * std::max(lambda_ref_, 0.0), 1e-12);
    if (v.size() == exu_.rows() && lambda0 < floor && lambda0 != 0.0) {
      const double corr = 1.0 / floor - 1.0 / lambda0;
      for (int j = 0; j < exu_.cols(); ++j) vexu_[j] = v.dot(exu_.col(j));
      for (int j = 0; j < quad_.cols(); ++j) {
        for (int i = 0; i < quad_.rows(); ++i) quad_(i, j) += corr * (vexu_[i] * vexu_[j]);
      }
      result_.stiffness_regularized = true;
    }
  }
  have_tangent_ = ok;
  tangent_in_sol_ = false;
  Mat& k = result_.stiffness;
  if (ok) {
    // -(E_uu - E_ux E_xx^-1 E_xu), element by element (no temporaries, no allocation).
    for (int j = 0; j < k.cols(); ++j) {
      for (int i = 0; i < k.rows(); ++i) k(i, j) = quad_(i, j) - euu_(i, j);
    }
  }
  if (!ok || !k.allFinite()) {
    // No usable factorisation: the stiffness with the state held (no response), finite.
    k = -euu_;
    result_.stiffness_regularized = true;
  }
  // Symmetric part, in place: (K + K^T) / 2.
  for (int j = 0; j < k.cols(); ++j) {
    for (int i = j + 1; i < k.rows(); ++i) k(i, j) = k(j, i) = 0.5 * (k(i, j) + k(j, i));
  }
}

}  // namespace snapthread
