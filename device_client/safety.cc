#include "safety.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "messages/validate.h"
#include "snap_ahead.h"

namespace snapthread::device {

bool SafetyLimits::IsValid(std::string* error) const {
  auto bad = [&](const char* what) {
    if (error) *error = std::string("safety limits: ") + what;
    return false;
  };
  if (!(max_force_n > 0.0) || !std::isfinite(max_force_n)) return bad("max_force_n must be > 0");
  if (!(max_stiffness_n_per_m >= 0.0) || !std::isfinite(max_stiffness_n_per_m)) {
    return bad("max_stiffness_n_per_m must be >= 0");
  }
  if (!(max_force_rate_n_per_s > 0.0) || !std::isfinite(max_force_rate_n_per_s)) {
    return bad("max_force_rate_n_per_s must be > 0");
  }
  if (!(model_timeout_s > 0.0) || !std::isfinite(model_timeout_s)) {
    return bad("model_timeout_s must be > 0");
  }
  if (!(fade_time_s > 0.0) || !std::isfinite(fade_time_s)) return bad("fade_time_s must be > 0");
  if (!(workspace_radius_m > 0.0) || !std::isfinite(workspace_radius_m)) {
    return bad("workspace_radius_m must be > 0");
  }
  if (!(max_torque_nm >= 0.0) || !std::isfinite(max_torque_nm)) return bad("max_torque_nm must be >= 0");
  if (!(tick_period_s > 0.0) || !std::isfinite(tick_period_s)) return bad("tick_period_s must be > 0");
  return true;
}

SafetyLimits LimitsFrom(const DeviceCapabilities& caps, const DeviceMapping* mapping) {
  SafetyLimits l;
  l.max_force_n = caps.max_force_n;
  l.max_stiffness_n_per_m = caps.max_stiffness_n_per_m;
  l.workspace_radius_m = caps.workspace_radius_m;
  if (mapping != nullptr) {
    l.max_force_n = std::min(l.max_force_n, mapping->max_force_n);
    l.max_stiffness_n_per_m = std::min(l.max_stiffness_n_per_m, mapping->max_stiffness_n_per_m);
    l.workspace_radius_m = std::min(l.workspace_radius_m, mapping->workspace_radius_m);
  }
  return l;
}

bool ClampStiffness(const double K_in[3][3], const SafetyLimits& limits, double out[3][3],
                    bool* clamped, std::string* why) {
  // Stiffness S = -sym(K); clamp its eigenvalues to [0, max stable stiffness].
  Eigen::Matrix3d K;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) K(i, j) = K_in[i][j];
  }
  // Halved before adding: K + K^T overflows for entries above half the double range.
  const Eigen::Matrix3d S = -(0.5 * K + 0.5 * K.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(S);
  if (eig.info() != Eigen::Success || !eig.eigenvalues().allFinite() ||
      !eig.eigenvectors().allFinite()) {
    if (why) *why = "stiffness eigen-decomposition failed";
    return false;
  }
  Eigen::Vector3d lambda = eig.eigenvalues();
  *clamped = false;
  // Round-off tolerance: a symmetric K computed in double carries ~1e-12 relative noise.
  const double tol = 1e-9 * std::max(1.0, limits.max_stiffness_n_per_m);
  for (int i = 0; i < 3; ++i) {
    const double c = std::clamp(lambda[i], 0.0, limits.max_stiffness_n_per_m);
    if (std::abs(c - lambda[i]) > tol) *clamped = true;
    lambda[i] = c;
  }
  const Eigen::Matrix3d S_clamped =
      eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out[i][j] = -0.5 * (S_clamped(i, j) + S_clamped(j, i));
  }
  // The servo trusts K to be finite (an absurd K must never become a NaN force).
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (!std::isfinite(out[i][j])) {
        if (why) *why = "K is not finite after clamping its stiffness";
        return false;
      }
    }
  }
  return true;
}

ModelVerdict PrepareModel(const force_model_t& msg, int64_t receive_us,
                          const SafetyLimits& limits, LocalModel* out, std::string* why) {
  if (!transport::Validate(msg, why)) return ModelVerdict::kRejected;
  LocalModel m;
  m.seq = msg.seq;
  m.device_seq = msg.device_seq;
  m.device_utime_us = msg.device_utime;
  m.receive_us = receive_us;
  m.status = msg.status;
  if (msg.status == force_model_t::STATUS_INVALID) {
    // No equilibrium: the message definition says render zero force. The zero model
    // still refreshes the watchdog (the server is alive) and the slew limit takes the
    // force down smoothly.
    for (int i = 0; i < 3; ++i) m.u0_m[i] = msg.u0[i];
    *out = m;
    return ModelVerdict::kInvalidStatus;
  }
  m.has_torque = msg.has_torque == 1;
  for (int i = 0; i < 3; ++i) {
    m.u0_m[i] = msg.u0[i];
    m.f0_n[i] = msg.f0[i];
    m.torque0_nm[i] = m.has_torque ? msg.torque0[i] : 0.0;
  }
  bool clamped = false;
  if (!ClampStiffness(msg.K, limits, m.K_n_per_m, &clamped, why)) return ModelVerdict::kRejected;
  // A bad fold refuses the whole model: it never reaches the servo (snap_ahead.h).
  if (!PrepareFold(msg, limits, &m, &clamped, why)) return ModelVerdict::kRejected;
  *out = m;
  return clamped ? ModelVerdict::kStiffnessClamped : ModelVerdict::kAccepted;
}

ForceSafety::ForceSafety(const SafetyLimits& limits, bool device_has_orientation)
    : limits_(limits), has_orientation_(device_has_orientation) {
  std::string error;
  if (!limits_.IsValid(&error)) throw std::invalid_argument(error);
}

namespace {
void Bump(std::atomic<uint64_t>& c) { c.fetch_add(1, std::memory_order_relaxed); }
}  // namespace

void ForceSafety::Step(const double position_m[3], bool pose_ok, const LocalModel* model,
                       int64_t now_us, SafetyOutput* out) {
  *out = SafetyOutput{};
  // Elapsed time drives the fade (a stalled thread must not freeze the fade).
  double dt_s = limits_.tick_period_s;
  if (last_now_us_ >= 0) {
    dt_s = std::clamp(1e-6 * static_cast<double>(now_us - last_now_us_), 0.0, limits_.fade_time_s);
  }
  last_now_us_ = now_us;

  // Watchdog: fade out on a stale (or missing) model, fade back in on a fresh one.
  bool stale = true;
  if (model != nullptr) {
    out->model_age_ms = 1e-3 * static_cast<double>(now_us - model->receive_us);
    out->model_status = model->status;
    stale = out->model_age_ms > 1e3 * limits_.model_timeout_s;
    out->fading = stale;
    if (stale) Bump(counters_.fade_ticks);
  }
  // Stopping: fade out as for a stale model (the trace shows it as fading).
  if (fade_out_.load(std::memory_order_relaxed)) {
    stale = true;
    out->fading = true;
  }
  const double dgain = dt_s / limits_.fade_time_s;
  gain_ = std::clamp(stale ? gain_ - dgain : gain_ + dgain, 0.0, 1.0);
  out->gain = gain_;

  // A pose we cannot trust: no force from the model (fades below, at the slew limit).
  bool pose_good = pose_ok;
  if (pose_good) {
    double r2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(position_m[k])) pose_good = false;
      r2 += position_m[k] * position_m[k];
    }
    if (pose_good && r2 > limits_.workspace_radius_m * limits_.workspace_radius_m) {
      pose_good = false;
    }
  }
  if (!pose_good) {
    out->pose_rejected = true;
    Bump(counters_.poses_rejected);
    // No trusted position to evaluate the model at: the force only fades, toward zero at
    // the slew limit (the envelope |F(t) - F(t-1)| <= max rate x tick holds here too), so a
    // glitching encoder neither pushes on nor jerks the hand.
    const double step = limits_.max_force_rate_n_per_s * limits_.tick_period_s;
    const double n = std::sqrt(last_force_n_[0] * last_force_n_[0] +
                               last_force_n_[1] * last_force_n_[1] +
                               last_force_n_[2] * last_force_n_[2]);
    const double keep = (std::isfinite(n) && n > step) ? (n - step) / n : 0.0;
    for (int k = 0; k < 3; ++k) {
      last_force_n_[k] *= keep;
      out->force_n[k] = last_force_n_[k];
    }
    return;
  }

  // F = f0 + K (u - u0), scaled by the fade gain.
  double f[3] = {0.0, 0.0, 0.0};
  if (model != nullptr && gain_ > 0.0) {
    double du[3];
    for (int k = 0; k < 3; ++k) du[k] = position_m[k] - model->u0_m[k];
    for (int i = 0; i < 3; ++i) {
      double fi = model->f0_n[i];
      for (int j = 0; j < 3; ++j) fi += model->K_n_per_m[i][j] * du[j];
      f[i] = gain_ * fi;
    }
  }

  // |F| <= max force.
  double norm = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  if (!std::isfinite(norm)) {
    // f0 + K du overflowed (absurd but finite inputs): no direction to keep, so aim at
    // zero and let the slew limit take the force there.
    for (double& fi : f) fi = 0.0;
    out->clamped = true;
    Bump(counters_.force_clamps);
  } else if (norm > limits_.max_force_n) {
    const double s = limits_.max_force_n / norm;
    for (double& fi : f) fi *= s;
    out->clamped = true;
    Bump(counters_.force_clamps);
  }

  // |F - F_previous| <= max rate * tick period.
  const double max_step = limits_.max_force_rate_n_per_s * limits_.tick_period_s;
  double d[3], dn2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    d[k] = f[k] - last_force_n_[k];
    dn2 += d[k] * d[k];
  }
  if (dn2 > max_step * max_step) {
    const double s = max_step / std::sqrt(dn2);
    for (int k = 0; k < 3; ++k) f[k] = last_force_n_[k] + s * d[k];
    out->slew_limited = true;
    Bump(counters_.slew_limits);
  }

  // Last line of defence: never a non-finite force (e.g. an overflow in f0 + K du).
  bool finite = true;
  for (double fi : f) finite = finite && std::isfinite(fi);
  if (!finite) {
    Bump(counters_.nonfinite_outputs);
    for (double& fi : f) fi = 0.0;
  }
  for (int k = 0; k < 3; ++k) {
    out->force_n[k] = f[k];
    last_force_n_[k] = f[k];
  }
  norm = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  if (norm > max_force_n_.load(std::memory_order_relaxed)) {
    max_force_n_.store(norm, std::memory_order_relaxed);
  }

  // Grip torque: constant over the model (force_model_t has no torque stiffness), faded
  // with the force and bounded.
  if (has_orientation_ && model != nullptr && model->has_torque) {
    double t[3], tn2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      t[k] = gain_ * model->torque0_nm[k];
      tn2 += t[k] * t[k];
    }
    if (!std::isfinite(tn2)) tn2 = 0.0, t[0] = t[1] = t[2] = 0.0;
    const double tn = std::sqrt(tn2);
    const double s = tn > limits_.max_torque_nm ? limits_.max_torque_nm / tn : 1.0;
    for (int k = 0; k < 3; ++k) out->torque_nm[k] = s * t[k];
  }
}

}  // namespace snapthread::device
