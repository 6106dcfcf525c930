// SolverBase's accuracy: the convergence test in force units, the certified force error
// of a state from its own factorisation, and the round-off floor of the gradient
// (docs/accuracy.md).
#include "solvers/solver_base.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace snapthread {
namespace {

// The estimate is this many times the first-order force change of the Newton correction
// (or the force change to the corrected state, where E_u curves): the correction itself
// is exact only to first order near a fold or in a flat valley (docs/accuracy.md).
constexpr double kForceErrorMargin = 2.0;
// The force's own round-off, in units of eps times (|F| + force scale): below this no
// two evaluations of F agree, so no estimate is smaller.
constexpr double kForceRoundOff = 16.0;
// The force change to the corrected state this many times the first-order one marks a
// correction long along a soft mode, whose length the reduced quartic caps.
constexpr double kCurvedCorrection = 4.0;
constexpr double kEps = std::numeric_limits<double>::epsilon();
// The round-off probe moves each coordinate by this many units in its last place: the
// gradient sums many terms, each with its own rounding, so one unit understates it.
constexpr double kRoundOffUlps = 8.0;

}  // namespace

bool SolverBase::Converged(double r, const Vec& x, const Vec& u, SolverSummary* s) {
  if (!(r < options_.cutoff)) return false;
  if (!(force_target_ > 0.0)) return true;
  // E_xx at x, factorised here, serves the iteration that follows if this one fails.
  // Where it cannot be factorised (singular to working precision: a symmetric state on
  // its axis) no force error can be certified and the cutoff alone decides, as before.
  if (FactorAt(x, u, s) != LinearSolverStatus::kSuccess) return true;
  return ForceCertified(x, u);
}

bool SolverBase::ForceCertified(const Vec& x, const Vec& u) {
  if (!(force_target_ > 0.0)) return true;
  const double e = ForceErrorFromFactor(x, u);
  return e < 0.0 || e <= force_target_;
}

double SolverBase::ForceErrorFromFactor(const Vec& x, const Vec& u) {
  Workspace& w = ws_;
  if (err_serial_ == factor_serial_ && std::memcmp(x.data(), w.err_state.data(), sizeof(double) * n_) == 0)
    return err_value_;
  // dx = E_xx^-1 E_x: the Newton correction (2.18) of x; x - dx is the equilibrium to
  // first order, and the force F = -E_u moves by E_ux dx on the way there (2.14-2.15).
  if (w.factor->Solve(w.g, &w.err_dx) != LinearSolverStatus::kSuccess || !w.err_dx.allFinite()) return -1.0;
  model_.MixedHessian(x, u, &w.exu);
  w.err_df.noalias() = w.exu.transpose() * w.err_dx;
  const double linear = w.err_df.lpNorm<Eigen::Infinity>();
  // Where E_u curves over the correction (a flat valley, a fold), the force change to the
  // corrected state itself: two evaluations of E_u, a few terms at the grasp.
  model_.ControlGradient(x, u, &w.err_eu0);
  double change = ForceChangeAlongCorrection(x, u, 1.0);
  // That change far above the first-order one: the correction is long along a soft mode
  // and the force curves over it. There the correction overshoots where the energy
  // stiffens beyond its quadratic (the reduced quartic of (2.54)-(2.55)): its length is
  // capped at the root of the reduced equation, and the change taken there.
  if (change > kCurvedCorrection * linear) change = ForceChangeAlongCorrection(x, u, CappedCorrection(x, u));
  const double round_off = kForceRoundOff * kEps * (w.err_eu0.lpNorm<Eigen::Infinity>() + model_.ForceScale());
  err_value_ = kForceErrorMargin * std::max(linear, change) + round_off;
  if (!std::isfinite(err_value_)) err_value_ = -1.0;
  err_serial_ = factor_serial_;
  w.err_state = x;
  return err_value_;
}

double SolverBase::ForceChangeAlongCorrection(const Vec& x, const Vec& u, double t) {
  Workspace& w = ws_;
  w.err_x = x - t * w.err_dx;
  model_.ControlGradient(w.err_x, u, &w.err_eu1);
  const double change = (w.err_eu1 - w.err_eu0).lpNorm<Eigen::Infinity>();
  return std::isfinite(change) ? change : 0.0;
}

double SolverBase::CappedCorrection(const Vec& x, const Vec& u) {
  // The reduced energy along the correction, e(t) = E(x - t dx) - E(x), is
  // -c t + c t^2 / 2 + gamma_3 t^3 + gamma_4 t^4 with c = dx . E_x = dx . E_xx dx (the
  // seed's (2.54)-(2.55) along dx). One gradient at the corrected state gives
  // e'(1) = 3 gamma_3 + 4 gamma_4 = -dx . E_x(x - dx) =: q. Where q > 0 the energy stiffens
  // and the equilibrium lies short of t = 1: e'(t) = c (t - 1) + q t^3 = 0 (the quartic
  // alone, the longer of the two one-term models, so the cap errs on the long side).
  // Elsewhere (q <= 0, c <= 0: softening, indefinite) the whole correction is kept.
  Workspace& w = ws_;
  const double c = w.err_dx.dot(w.g);
  w.err_x = x - w.err_dx;
  model_.Gradient(w.err_x, u, &w.noise_g);
  const double q = -w.err_dx.dot(w.noise_g);
  if (!(c > 0.0) || !(q > 0.0) || !std::isfinite(q)) return 1.0;
  double lo = 0.0, hi = 1.0;  // c (t - 1) + q t^3 rises from -c to q: one root in (0, 1)
  for (int i = 0; i < 40; ++i) {
    const double t = 0.5 * (lo + hi);
    (c * (t - 1.0) + q * t * t * t > 0.0 ? hi : lo) = t;
  }
  return hi;
}

bool SolverBase::AtRoundOff(double r, const Vec& x, const Vec& u, SolverSummary* s) {
  // Every coordinate moved by a few units in its last place (of at least 1: a coordinate near
  // 0 is known to the round-off of the positions it is computed with), in alternating
  // directions, which excites the stiffest modes: the gradient's change is the size of
  // its round-off at x, the least |E_x| double precision can certify there.
  Workspace& w = ws_;
  for (int i = 0; i < n_; ++i) {
    const double step = kRoundOffUlps * kEps * std::max(std::abs(x[i]), 1.0);
    w.noise_x[i] = x[i] + ((i % 2) == 0 ? step : -step);
  }
  model_.Gradient(w.noise_x, u, &w.noise_g);
  ++s->gradient_evaluations;
  w.noise_g -= w.g;
  const double floor = w.noise_g.norm();
  s->round_off_floor = floor;
  return std::isfinite(floor) && r <= floor;
}

void SolverBase::StopAtRoundOff(SolverSummary* s) {
  s->termination = Termination::kConverged;
  s->at_round_off = true;
  s->message = "converged to the gradient's round-off";
}

}  // namespace snapthread
