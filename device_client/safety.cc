#include "safety.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace snapthread::device {
namespace {
void Bump(std::atomic<uint64_t>& c) { c.fetch_add(1, std::memory_order_relaxed); }
}  // namespace

ForceSafety::ForceSafety(const SafetyLimits& limits, bool device_has_orientation, bool torque_output)
    : limits_(limits),
      has_orientation_(device_has_orientation),
      torque_output_(torque_output),
      force_limiter_(limits.max_force_n, limits.max_force_rate_n_per_s * limits.tick_period_s),
      torque_limiter_(limits.max_torque_nm, limits.max_torque_rate_nm_per_s * limits.tick_period_s) {
  std::string error;
  if (!limits_.IsValid(&error)) throw std::invalid_argument(error);
}

void ForceSafety::Step(const double position_m[3], const double orientation[4], bool pose_ok,
                       const LocalModel* model, int64_t now_us, SafetyOutput* out) {
  *out = SafetyOutput{};
  UpdateGain(model, now_us, out);
  if (!PoseGood(position_m, orientation, pose_ok)) {
    out->pose_rejected = true;
    Bump(counters_.poses_rejected);
    FadeOnBadPose(out);
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
  Render(force_limiter_, f, out->force_n, &out->clamped, &out->slew_limited, counters_.force_clamps,
         counters_.slew_limits);
  const double norm = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  if (norm > max_force_n_.load(std::memory_order_relaxed)) {
    max_force_n_.store(norm, std::memory_order_relaxed);
  }
  // The torque the same way, at its own bound and slew limit.
  if (torque_output_) {
    Render(torque_limiter_, t, out->torque_nm, &out->torque_clamped, &out->torque_slew_limited,
           counters_.torque_clamps, counters_.torque_slew_limits);
  }
}

void ForceSafety::UpdateGain(const LocalModel* model, int64_t now_us, SafetyOutput* out) {
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
}

bool ForceSafety::PoseGood(const double position_m[3], const double orientation[4], bool pose_ok) const {
  if (!pose_ok) return false;
  bool good = true;
  double r2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(position_m[k])) good = false;
    r2 += position_m[k] * position_m[k];
  }
  if (good && r2 > limits_.workspace_radius_m * limits_.workspace_radius_m) good = false;
  // The orientation is part of the pose where the model uses it.
  if (good && has_orientation_ && orientation != nullptr) {
    for (int k = 0; k < 4; ++k) good = good && std::isfinite(orientation[k]);
  }
  return good;
}

void ForceSafety::FadeOnBadPose(SafetyOutput* out) {
  // No trusted position to evaluate the model at: the force only fades, toward zero at
  // the slew limit (the envelope |F(t) - F(t-1)| <= max rate x tick holds here too), so a
  // glitching encoder neither pushes on nor jerks the hand. (The fade is not counted as
  // a slew-limit event: it is the pose rejection, counted by Step.)
  double f[3] = {0.0, 0.0, 0.0};
  force_limiter_.Apply(f);
  for (int k = 0; k < 3; ++k) out->force_n[k] = f[k];
  // The torque the same way, at its own slew limit.
  if (torque_output_) {
    double t[3] = {0.0, 0.0, 0.0};
    torque_limiter_.Apply(t);
    for (int k = 0; k < 3; ++k) out->torque_nm[k] = t[k];
  }
}

void ForceSafety::Render(VectorLimiter& limiter, double v[3], double out_v[3], bool* clamped, bool* slewed,
                         std::atomic<uint64_t>& clamps, std::atomic<uint64_t>& slews) {
  const LimitVerdict l = limiter.Apply(v);
  if (l.clamped) {
    *clamped = true;
    Bump(clamps);
  }
  if (l.slew_limited) {
    *slewed = true;
    Bump(slews);
  }
  if (l.nonfinite) Bump(counters_.nonfinite_outputs);
  for (int k = 0; k < 3; ++k) out_v[k] = v[k];
}

}  // namespace snapthread::device
