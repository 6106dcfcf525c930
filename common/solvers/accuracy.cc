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
// correction long along a soft mode over which the force curves: a second correction
// (SecondOrderForceChange) checks it.
constexpr double kCurvedCorrection = 4.0;
// Two corrections that shrink by less than this do not contract: no second-order estimate.
constexpr double kMaxContraction = 0.5;
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
  w.err_x = x - w.err_dx;
  model_.ControlGradient(w.err_x, u, &w.err_eu1);
  double change = (w.err_eu1 - w.err_eu0).lpNorm<Eigen::Infinity>();
  if (!std::isfinite(change)) change = 0.0;
  if (change > kCurvedCorrection * linear) change = SecondOrderForceChange(u, change);
  const double round_off = kForceRoundOff * kEps * (w.err_eu0.lpNorm<Eigen::Infinity>() + model_.ForceScale());
  err_value_ = kForceErrorMargin * std::max(linear, change) + round_off;
  if (!std::isfinite(err_value_)) err_value_ = -1.0;
  err_serial_ = factor_serial_;
  w.err_state = x;
  return err_value_;
}

double SolverBase::SecondOrderForceChange(const Vec& u, double first) {
  // The correction is long along a soft mode and the force curves over it. x - dx lies on
  // the straight chord of a curved valley (a soft mode that turns the shape: moving
  // nodes along the chord stretches segments), and E_u there carries that spurious
  // stretch. A second correction from x - dx with the same factorisation (a chord step:
  // one gradient, one solve) brings it back into the valley; the force change to
  // x - dx - dx2 is then the second-order estimate. The steps' contraction
  // q = |dx2| / |dx| bounds what is left: a further q / (1 - q) of the second step's
  // force change. Where they do not contract (q >= 1/2) the first change stands.
  // Scratch: the round-off probe's vectors (AtRoundOff writes them afresh when it runs).
  Workspace& w = ws_;
  model_.Gradient(w.err_x, u, &w.noise_g);
  if (w.factor->Solve(w.noise_g, &w.noise_x) != LinearSolverStatus::kSuccess || !w.noise_x.allFinite())
    return first;
  // Its part along dx (the soft mode itself, amplified by 1 / lambda_min from the chord's
  // stretch) is not a correction but the chord's artefact: only the rest is taken.
  const double dx2 = w.err_dx.squaredNorm();
  if (!(dx2 > 0.0)) return first;
  w.noise_x -= (w.noise_x.dot(w.err_dx) / dx2) * w.err_dx;
  const double q = w.noise_x.norm() / std::sqrt(dx2);
  if (!(q < kMaxContraction)) return first;
  w.err_x -= w.noise_x;
  model_.ControlGradient(w.err_x, u, &w.err_df);
  const double second = (w.err_df - w.err_eu0).lpNorm<Eigen::Infinity>();
  const double last_step = (w.err_df - w.err_eu1).lpNorm<Eigen::Infinity>();
  const double change = second + q / (1.0 - q) * last_step;
  return std::isfinite(change) ? change : first;
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
