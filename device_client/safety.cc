#include "safety.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "messages/validate.h"
#include "numeric/so3.h"
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
  if (!(max_torque_rate_nm_per_s > 0.0) || !std::isfinite(max_torque_rate_nm_per_s)) {
    return bad("max_torque_rate_nm_per_s must be > 0");
  }
  if (!(max_torque_stiffness_nm_per_rad >= 0.0) || !std::isfinite(max_torque_stiffness_nm_per_rad)) {
    return bad("max_torque_stiffness_nm_per_rad must be >= 0");
  }
  if (!(tick_period_s > 0.0) || !std::isfinite(tick_period_s)) return bad("tick_period_s must be > 0");
  return true;
}

SafetyLimits LimitsFrom(const DeviceCapabilities& caps, const DeviceMapping* mapping,
                        const SafetyLimits& base) {
  SafetyLimits l = base;
  l.max_force_n = caps.max_force_n;
  l.max_stiffness_n_per_m = caps.max_stiffness_n_per_m;
  l.workspace_radius_m = caps.workspace_radius_m;
  // A device without torque output renders none; one with it, no more than it can.
  l.max_torque_nm = caps.has_torque_output ? std::min(l.max_torque_nm, caps.max_torque_nm) : 0.0;
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

bool ClampWrenchStiffness(const double K6_in[6][6], const SafetyLimits& limits, double out[6][6],
                          bool* clamped, std::string* why) {
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  Mat6 k;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) k(i, j) = K6_in[i][j];
  }
  const double k_max = limits.max_stiffness_n_per_m;
  const double k_rot = limits.max_torque_stiffness_nm_per_rad;
  *clamped = false;
  Mat6 result = Mat6::Zero();
  if (k_max > 0.0 && k_rot > 0.0) {
    // (u, ℓ r) with ℓ² = k_rot / k_max: K6' = T K6 T, T = diag(1, 1, 1, 1/ℓ, 1/ℓ, 1/ℓ), all
    // in N/m; -sym(K6') in [0, k_max] <=> the force block in [0, k_max] N/m and the
    // torque block in [0, k_rot] N m/rad, with a coupling that keeps the whole PSD.
    const double ell = std::sqrt(k_rot / k_max);
    Eigen::Matrix<double, 6, 1> t;
    t << 1.0, 1.0, 1.0, 1.0 / ell, 1.0 / ell, 1.0 / ell;
    const Mat6 kp = t.asDiagonal() * k * t.asDiagonal();
    const Mat6 sym = -(0.5 * kp + 0.5 * kp.transpose());
    Mat6 skew = 0.5 * kp - 0.5 * kp.transpose();
    Eigen::SelfAdjointEigenSolver<Mat6> eig(sym);
    if (eig.info() != Eigen::Success || !eig.eigenvalues().allFinite() || !eig.eigenvectors().allFinite()) {
      if (why) *why = "K6 stiffness eigen-decomposition failed";
      return false;
    }
    Eigen::Matrix<double, 6, 1> lambda = eig.eigenvalues();
    const double tol = 1e-9 * std::max(1.0, k_max);
    for (int i = 0; i < 6; ++i) {
      const double c = std::clamp(lambda[i], 0.0, k_max);
      if (std::abs(c - lambda[i]) > tol) *clamped = true;
      lambda[i] = c;
    }
    // -½[τ0]× has Frobenius norm |τ0| / √2; in K6' it is divided by ℓ².
    const double skew_max = limits.max_torque_nm / (std::sqrt(2.0) * ell * ell);
    const double skew_norm = skew.norm();
    if (!std::isfinite(skew_norm)) {
      if (why) *why = "K6 is not finite";
      return false;
    }
    if (skew_norm > skew_max * (1.0 + 1e-9)) {
      skew *= skew_max / skew_norm;
      *clamped = true;
    }
    const Mat6 s = eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
    const Mat6 kc = -(0.5 * s + 0.5 * s.transpose()) + skew;
    result = t.cwiseInverse().asDiagonal() * kc * t.cwiseInverse().asDiagonal();
  } else {
    double k3[3][3], c3[3][3];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) k3[i][j] = K6_in[i][j];
    }
    if (!ClampStiffness(k3, limits, c3, clamped, why)) return false;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) result(i, j) = c3[i][j];
    }
    if (!(k.bottomRows<3>().isZero(0.0) && k.topRightCorner<3, 3>().isZero(0.0))) *clamped = true;
  }
  if (!result.allFinite()) {
    if (why) *why = "K6 is not finite after clamping its stiffness";
    return false;
  }
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) out[i][j] = result(i, j);
  }
  return true;
}

ModelVerdict PrepareModel(const force_model_t& msg, int64_t receive_us,
                          const SafetyLimits& limits, LocalModel* out, std::string* why) {
  if (!messages::Validate(msg, why)) return ModelVerdict::kRejected;
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
  if (msg.has_wrench == 1) {
    // Validate() checked q0 is a unit quaternion and K6 finite.
    m.has_wrench = true;
    const double qn = std::sqrt(msg.q0[0] * msg.q0[0] + msg.q0[1] * msg.q0[1] +
                                msg.q0[2] * msg.q0[2] + msg.q0[3] * msg.q0[3]);
    for (int i = 0; i < 4; ++i) m.q0[i] = msg.q0[i] / qn;
    bool k6_clamped = false;
    if (!ClampWrenchStiffness(msg.K6, limits, m.K6, &k6_clamped, why)) return ModelVerdict::kRejected;
    clamped = clamped || k6_clamped;
  }
  // A bad fold refuses the whole model: it never reaches the servo (snap_ahead.h).
  if (!PrepareFold(msg, limits, &m, &clamped, why)) return ModelVerdict::kRejected;
  *out = m;
  return clamped ? ModelVerdict::kStiffnessClamped : ModelVerdict::kAccepted;
}

void EvaluateLocalModel(const LocalModel& model, const double position_m[3], const double orientation[4],
                        double force_n[3], double torque_nm[3]) {
  double d[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  for (int k = 0; k < 3; ++k) d[k] = position_m[k] - model.u0_m[k];
  const bool six = model.has_wrench && orientation != nullptr;
  if (six) {
    const Eigen::Vector3d r = so3::RotationVectorBetween(orientation, model.q0);
    for (int k = 0; k < 3; ++k) d[3 + k] = r[k];
  }
  for (int i = 0; i < 3; ++i) {
    double fi = model.f0_n[i];
    double ti = model.has_torque ? model.torque0_nm[i] : 0.0;
    if (six) {
      for (int j = 0; j < 6; ++j) {
        fi += model.K6[i][j] * d[j];
        ti += model.K6[3 + i][j] * d[j];
      }
    } else {
      for (int j = 0; j < 3; ++j) fi += model.K_n_per_m[i][j] * d[j];
    }
    force_n[i] = fi;
    torque_nm[i] = ti;
  }
}

ForceSafety::ForceSafety(const SafetyLimits& limits, bool device_has_orientation, bool torque_output)
    : limits_(limits), has_orientation_(device_has_orientation), torque_output_(torque_output) {
  std::string error;
  if (!limits_.IsValid(&error)) throw std::invalid_argument(error);
}

namespace {
void Bump(std::atomic<uint64_t>& c) { c.fetch_add(1, std::memory_order_relaxed); }
}  // namespace

Limited LimitVector(double v[3], double max_norm, double max_step, double last[3]) {
  Limited l;
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!std::isfinite(n)) {
    // An overflow upstream (absurd but finite inputs): aim at zero through the slew limit.
    v[0] = v[1] = v[2] = 0.0;
    l.clamped = true;
  } else if (n > max_norm) {
    const double s = max_norm / n;
    for (int k = 0; k < 3; ++k) v[k] *= s;
    l.clamped = true;
  }
  double d[3], dn2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    d[k] = v[k] - last[k];
    dn2 += d[k] * d[k];
  }
  if (dn2 > max_step * max_step) {
    const double s = max_step / std::sqrt(dn2);
    for (int k = 0; k < 3; ++k) v[k] = last[k] + s * d[k];
    l.slew_limited = true;
  }
  // Last line of defence: never a non-finite output.
  if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
    v[0] = v[1] = v[2] = 0.0;
    l.nonfinite = true;
  }
  for (int k = 0; k < 3; ++k) last[k] = v[k];
  return l;
}

void ForceSafety::Step(const double position_m[3], const double orientation[4], bool pose_ok,
                       const LocalModel* model, int64_t now_us, SafetyOutput* out) {
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
    // The orientation is part of the pose where the model uses it.
    if (pose_good && has_orientation_ && orientation != nullptr) {
      for (int k = 0; k < 4; ++k) pose_good = pose_good && std::isfinite(orientation[k]);
    }
  }
  if (!pose_good) {
    out->pose_rejected = true;
    Bump(counters_.poses_rejected);
    // No trusted position to evaluate the model at: the force only fades, toward zero at
    // the slew limit (the envelope |F(t) - F(t-1)| <= max rate x tick holds here too), so a
    // glitching encoder neither pushes on nor jerks the hand. (The fade is not counted as
    // a slew-limit event: it is the pose rejection, counted above.)
    double f[3] = {0.0, 0.0, 0.0};
    LimitVector(f, limits_.max_force_n, limits_.max_force_rate_n_per_s * limits_.tick_period_s,
                last_force_n_);
    for (int k = 0; k < 3; ++k) out->force_n[k] = f[k];
    // The torque the same way, at its own slew limit.
    if (torque_output_) {
      double t[3] = {0.0, 0.0, 0.0};
      LimitVector(t, limits_.max_torque_nm, limits_.max_torque_rate_nm_per_s * limits_.tick_period_s,
                  last_torque_nm_);
      for (int k = 0; k < 3; ++k) out->torque_nm[k] = t[k];
    }
    return;
  }

  // The local model, scaled by the fade gain.
  double f[3] = {0.0, 0.0, 0.0};
  double t[3] = {0.0, 0.0, 0.0};
  if (model != nullptr && gain_ > 0.0) {
    EvaluateLocalModel(*model, position_m, has_orientation_ ? orientation : nullptr, f, t);
    for (int k = 0; k < 3; ++k) {
      f[k] *= gain_;
      t[k] *= gain_;
    }
  }

  // |F| <= max force, |F - F_previous| <= max rate * tick, never non-finite.
  const Limited lf = LimitVector(f, limits_.max_force_n,
                                 limits_.max_force_rate_n_per_s * limits_.tick_period_s, last_force_n_);
  Count(lf, &out->clamped, &out->slew_limited, counters_.force_clamps, counters_.slew_limits);
  for (int k = 0; k < 3; ++k) out->force_n[k] = f[k];
  const double norm = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  if (norm > max_force_n_.load(std::memory_order_relaxed)) {
    max_force_n_.store(norm, std::memory_order_relaxed);
  }

  if (torque_output_) RenderTorque(t, out);
}

void ForceSafety::RenderTorque(double t[3], SafetyOutput* out) {
  const Limited lt = LimitVector(t, limits_.max_torque_nm,
                                 limits_.max_torque_rate_nm_per_s * limits_.tick_period_s, last_torque_nm_);
  Count(lt, &out->torque_clamped, &out->torque_slew_limited, counters_.torque_clamps,
        counters_.torque_slew_limits);
  for (int k = 0; k < 3; ++k) out->torque_nm[k] = t[k];
}

void ForceSafety::Count(const Limited& l, bool* clamped, bool* slewed, std::atomic<uint64_t>& clamps,
                        std::atomic<uint64_t>& slews) {
  if (l.clamped) {
    *clamped = true;
    Bump(clamps);
  }
  if (l.slew_limited) {
    *slewed = true;
    Bump(slews);
  }
  if (l.nonfinite) Bump(counters_.nonfinite_outputs);
}

}  // namespace snapthread::device
