// The device client's safety layer (shared/DESIGN.md "Forces and the device's local
// model"). Two halves:
//  * PrepareModel, off the servo thread, when a force model ARRIVES: refuses non-finite
//    or malformed models, turns STATUS_INVALID into a zero-force model, symmetrises K
//    and clamps its stiffness to the stable range. The servo tick then only evaluates.
//  * ForceSafety::Step, on the servo thread every tick (no allocation, no locks):
//    evaluates F = f0 + K (u - u0), fades it when the model is stale, clamps |F|,
//    slew-limits it, fades it to zero at the slew limit for a bad pose, and guarantees a
//    finite output.
//
// Sign convention: K = dF/du (force_model_t), so a passive spring has K negative
// semi-definite. The *stiffness* S = -sym(K) is what a haptic loop can render stably
// only when 0 <= S <= max_stiffness: S < 0 (energy-releasing, F pushing the hand further
// out) and S above the device's stable stiffness are what make a haptic loop unstable.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include "haptic_device.h"
#include "snapthread/force_model_t.hpp"
#include "scene/scene.h"

namespace snapthread::device {

struct SafetyLimits {
  double max_force_n = 3.0;
  double max_stiffness_n_per_m = 800.0;   // bound on the eigenvalues of S = -sym(K)
  // Slew limit. 1000 N/s = 1 N per 1 ms tick: a 3 N snap reaches the hand in 3 ms (felt
  // as a snap; the hand's bandwidth is ~10 Hz) but the device never sees a step.
  double max_force_rate_n_per_s = 1000.0;
  double model_timeout_s = 0.050;         // a model older than this starts fading
  double fade_time_s = 0.100;             // full force -> zero (and back) takes this long
  double workspace_radius_m = 0.08;       // poses farther from the origin get zero force
  double max_torque_nm = 0.05;            // grip torque bound (devices with orientation)
  double tick_period_s = 0.001;           // nominal servo period (slew per tick)

  bool IsValid(std::string* error) const;
};

// The device's limits tightened by the scene's DeviceMapping (the smaller of each).
// mapping may be null (no scene).
SafetyLimits LimitsFrom(const DeviceCapabilities& caps, const DeviceMapping* mapping);

// A force model as the servo tick uses it: already checked and clamped. Trivially
// copyable (handed over through a LatestValue).
struct LocalModel {
  int64_t seq = 0;
  int64_t device_seq = 0;
  int64_t device_utime_us = 0;  // echoed pose time (device CLOCK_MONOTONIC)
  int64_t receive_us = 0;       // device CLOCK_MONOTONIC when the model arrived
  int8_t status = force_model_t::STATUS_INVALID;
  bool has_torque = false;
  double u0_m[3] = {0.0, 0.0, 0.0};
  double f0_n[3] = {0.0, 0.0, 0.0};
  double K_n_per_m[3][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
  double torque0_nm[3] = {0.0, 0.0, 0.0};
  // Snap-ahead (issue 17, snap_ahead.h): the fold boundary and the post-snap model, checked
  // and with the post-snap stiffness clamped like K.
  bool has_fold = false;
  int64_t fold_id = 0;
  double fold_point_m[3] = {0.0, 0.0, 0.0};
  double fold_normal[3] = {0.0, 0.0, 0.0};
  double fold_curvature_per_m = 0.0;
  double post_u0_m[3] = {0.0, 0.0, 0.0};
  double post_f0_n[3] = {0.0, 0.0, 0.0};
  double post_K_n_per_m[3][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
};

// K (dF/du, N/m) with the stiffness S = -sym(K) clamped to [0, max stable stiffness] into
// out (finite); *clamped when a clamp acted. False (with *why) when it cannot be done.
bool ClampStiffness(const double K[3][3], const SafetyLimits& limits, double out[3][3],
                    bool* clamped, std::string* why);

enum class ModelVerdict {
  kAccepted,          // usable as sent (K symmetrised)
  kStiffnessClamped,  // usable, K's stiffness was clamped to [0, max]
  kInvalidStatus,     // STATUS_INVALID: usable as a zero-force model
  kRejected,          // not usable: never reaches the device
};

// Off the servo thread. Fills *out unless the verdict is kRejected (reason in *why).
ModelVerdict PrepareModel(const force_model_t& msg, int64_t receive_us,
                          const SafetyLimits& limits, LocalModel* out, std::string* why);

// Counters written by the servo thread, read by any thread.
struct SafetyCounters {
  std::atomic<uint64_t> force_clamps{0};       // ticks where |F| was clamped
  std::atomic<uint64_t> slew_limits{0};        // ticks where the slew limit acted
  std::atomic<uint64_t> fade_ticks{0};         // ticks with a stale model (fading or faded)
  std::atomic<uint64_t> poses_rejected{0};     // ticks with a NaN / out-of-workspace pose
  std::atomic<uint64_t> nonfinite_outputs{0};  // must stay 0: the last line of defence
};

// What one tick decided, for the trace and statistics.
struct SafetyOutput {
  double force_n[3] = {0.0, 0.0, 0.0};
  double torque_nm[3] = {0.0, 0.0, 0.0};
  double gain = 0.0;           // fade gain in [0, 1]
  double model_age_ms = -1.0;  // -1 when no model was ever received
  int8_t model_status = -1;    // -1 when none
  bool clamped = false;
  bool slew_limited = false;
  bool fading = false;         // the model is stale
  bool pose_rejected = false;
};

class ForceSafety {
 public:
  // limits must be valid (checked at start-up; std::invalid_argument otherwise).
  ForceSafety(const SafetyLimits& limits, bool device_has_orientation);

  // One servo tick. pose_ok is false when the device could not be read. model may be
  // null (none received yet). now_us: CLOCK_MONOTONIC. No allocation, no locks.
  void Step(const double position_m[3], bool pose_ok, const LocalModel* model, int64_t now_us,
            SafetyOutput* out);

  // From any thread: fade the force out as for a stale model, for good (a stop on
  // SIGINT/SIGTERM ends within the safety ramp instead of stepping to zero).
  void RequestFadeOut() { fade_out_.store(true, std::memory_order_relaxed); }

  const SafetyLimits& limits() const { return limits_; }
  const SafetyCounters& counters() const { return counters_; }
  // Largest |F| commanded so far, newtons (written by the servo thread).
  double max_force_n() const { return max_force_n_.load(std::memory_order_relaxed); }

 private:
  SafetyLimits limits_;
  bool has_orientation_;
  SafetyCounters counters_;
  std::atomic<double> max_force_n_{0.0};
  double last_force_n_[3] = {0.0, 0.0, 0.0};
  double gain_ = 0.0;  // starts at zero: the first model fades in
  std::atomic<bool> fade_out_{false};
  int64_t last_now_us_ = -1;
};

}  // namespace snapthread::device
