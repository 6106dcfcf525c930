// The device client's safety stage (shared/DESIGN.md "Forces and the device's local
// model"): ForceSafety::Step, on the servo thread every tick (no allocation, no locks),
// takes the local model (local_model.h; checked and stiffness-clamped when it arrived)
// at the hand's pose, fades it when the model is stale, clamps |F|, slew-limits it
// (limiter.h), fades it to zero at the slew limit for a bad pose, and guarantees a
// finite output. A device that senses its orientation renders a 6-DoF model's F with the
// rotation coupling; one with torque output (DeviceCapabilities::has_torque_output)
// renders τ too, with the force's guards: |τ| <= max_torque_nm, a torque slew limit, the
// same fade, and zero on anything non-finite.
#pragma once

#include <atomic>
#include <cstdint>

#include "limiter.h"
#include "local_model.h"
#include "safety_limits.h"

namespace snapthread::device {

// Counters written by the servo thread, read by any thread.
struct SafetyCounters {
  std::atomic<uint64_t> force_clamps{0};       // ticks where |F| was clamped
  std::atomic<uint64_t> slew_limits{0};        // ticks where the slew limit acted
  std::atomic<uint64_t> fade_ticks{0};         // ticks with a stale model (fading or faded)
  std::atomic<uint64_t> poses_rejected{0};     // ticks with a NaN / out-of-workspace pose
  std::atomic<uint64_t> nonfinite_outputs{0};  // must stay 0: the last line of defence
  std::atomic<uint64_t> torque_clamps{0};      // ticks where |τ| was clamped
  std::atomic<uint64_t> torque_slew_limits{0}; // ticks where the torque slew limit acted
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
  bool torque_clamped = false;
  bool torque_slew_limited = false;
};

class ForceSafety {
 public:
  // limits must be valid (checked at start-up; std::invalid_argument otherwise).
  // device_has_orientation: the device senses its orientation (the 6-DoF model's
  // rotation terms are used); torque_output: it renders torque (DeviceCapabilities).
  ForceSafety(const SafetyLimits& limits, bool device_has_orientation, bool torque_output = false);

  // One servo tick. pose_ok is false when the device could not be read. model may be
  // null (none received yet). now_us: CLOCK_MONOTONIC. No allocation, no locks.
  // orientation (w, x, y, z) may be null (a device that senses none: r = 0).
  void Step(const double position_m[3], const double orientation[4], bool pose_ok,
            const LocalModel* model, int64_t now_us, SafetyOutput* out);
  void Step(const double position_m[3], bool pose_ok, const LocalModel* model, int64_t now_us,
            SafetyOutput* out) {
    Step(position_m, nullptr, pose_ok, model, now_us, out);
  }

  // From any thread: fade the force out as for a stale model, for good (a stop on
  // SIGINT/SIGTERM ends within the safety ramp instead of stepping to zero).
  void RequestFadeOut() { fade_out_.store(true, std::memory_order_relaxed); }

  const SafetyLimits& limits() const { return limits_; }
  const SafetyCounters& counters() const { return counters_; }
  // Largest |F| commanded so far, newtons (written by the servo thread).
  double max_force_n() const { return max_force_n_.load(std::memory_order_relaxed); }
  bool torque_output() const { return torque_output_; }

 private:
  // The watchdog's fade gain for this tick (elapsed time since the last, the model's age,
  // a requested fade-out) into gain_ and *out.
  void UpdateGain(const LocalModel* model, int64_t now_us, SafetyOutput* out);
  // The pose can be trusted: read, finite, inside the workspace.
  bool PoseGood(const double position_m[3], const double orientation[4], bool pose_ok) const;
  // A pose that cannot be trusted: the output only fades toward zero at the slew limits.
  void FadeOnBadPose(SafetyOutput* out);
  // v (the model's force or torque, faded) through limiter into out_v; the verdict into
  // the tick's flags and the counters.
  void Render(VectorLimiter& limiter, double v[3], double out_v[3], bool* clamped, bool* slewed,
              std::atomic<uint64_t>& clamps, std::atomic<uint64_t>& slews);

  SafetyLimits limits_;
  bool has_orientation_;
  bool torque_output_;
  VectorLimiter force_limiter_;   // |F| <= max force, slew <= max rate x tick
  VectorLimiter torque_limiter_;  // |τ| <= max torque, slew <= max torque rate x tick
  SafetyCounters counters_;
  std::atomic<double> max_force_n_{0.0};
  double gain_ = 0.0;  // starts at zero: the first model fades in
  std::atomic<bool> fade_out_{false};
  int64_t last_now_us_ = -1;
};

}  // namespace snapthread::device
