// The device client's safety layer (shared/DESIGN.md "Forces and the device's local
// model"). Two halves:
//  * PrepareModel, off the servo thread, when a force model ARRIVES: refuses non-finite
//    or malformed models, turns STATUS_INVALID into a zero-force model, symmetrises K
//    and clamps its stiffness to the stable range. The servo tick then only evaluates.
//  * ForceSafety::Step, on the servo thread every tick (no allocation, no locks):
//    evaluates F = f0 + K (u - u0), fades it when the model is stale, clamps |F|,
//    slew-limits it, fades it to zero at the slew limit for a bad pose, and guarantees a
//    finite output.
//  * A full-pose grasp (the rod: force_model_t.has_wrench) is a 6-DoF local model about
//    the pose (u0, R0):  (F, τ) = (f0, τ0) + K6 (u - u0, r),  r = log(R R0ᵀ) from the
//    device's quaternion. A device that senses its orientation renders F with the
//    rotation coupling; one with torque output (DeviceCapabilities::has_torque_output)
//    renders τ too, with the force's guards: |τ| <= max_torque_nm, a torque slew limit, a
//    stiffness clamp on K6 (PrepareModel), the same fade, and zero on anything
//    non-finite. Without orientation sensing the device renders F = f0 + K (u - u0).
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
  double max_torque_nm = 0.05;            // grip torque bound (devices with torque output)
  // Torque slew limit: 20 N m/s = 0.02 N m per 1 ms tick (0.05 N m in 2.5 ms).
  double max_torque_rate_nm_per_s = 20.0;
  // Bound on the rotational stiffness -sym(dτ/dr) of K6, N m/rad (a conservative
  // default for a motorised wrist, not a measured device limit; --max-torque-stiffness).
  double max_torque_stiffness_nm_per_rad = 0.1;
  double tick_period_s = 0.001;           // nominal servo period (slew per tick)

  bool IsValid(std::string* error) const;
};

// The device's limits tightened by the scene's DeviceMapping (the smaller of each), the
// rest from `base` (defaults). mapping may be null (no scene). The torque bound is
// base's, no more than the device's own, and 0 for a device without torque output.
SafetyLimits LimitsFrom(const DeviceCapabilities& caps, const DeviceMapping* mapping,
                        const SafetyLimits& base = SafetyLimits{});

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
  // Full-pose grasp (has_wrench): the orientation the model is expanded about and
  // d(F, τ)/d(u, r) with its stiffness clamped (ClampWrenchStiffness); rows F then τ,
  // columns metres then radians.
  bool has_wrench = false;
  double q0[4] = {1.0, 0.0, 0.0, 0.0};
  double K6[6][6] = {};
  // Snap-ahead (issue 17, snap_ahead.h): the fold boundary and the post-snap model, checked
  // and with the post-snap stiffness clamped like K.
  bool has_fold = false;
  int64_t fold_id = 0;
  double fold_point_m[3] = {0.0, 0.0, 0.0};
  double fold_normal[3] = {0.0, 0.0, 0.0};
  double fold_curvature_per_m = 0.0;
  // A fold reached by turning: the orientation there and the normal's rotational part
  // (m/rad; (fold_normal, fold_normal_r) is a unit vector). has_fold_rotation: it is not 0.
  bool has_fold_rotation = false;
  double fold_q[4] = {1.0, 0.0, 0.0, 0.0};
  double fold_normal_r[3] = {0.0, 0.0, 0.0};
  double post_u0_m[3] = {0.0, 0.0, 0.0};
  double post_f0_n[3] = {0.0, 0.0, 0.0};
  double post_K_n_per_m[3][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
  double post_torque0_nm[3] = {0.0, 0.0, 0.0};  // with has_torque
};

// K (dF/du, N/m) with the stiffness S = -sym(K) clamped to [0, max stable stiffness] into
// out (finite); *clamped when a clamp acted. False (with *why) when it cannot be done.
bool ClampStiffness(const double K[3][3], const SafetyLimits& limits, double out[3][3],
                    bool* clamped, std::string* why);

// K6 (force_model_t, rows F then τ, columns metres then radians) made safe for a haptic
// loop, into out (finite): in the coordinates (u, ℓ r), ℓ² = max_torque_stiffness /
// max_stiffness, where both stiffness bounds are the one max_stiffness, the stiffness
// -sym(K6') has its eigenvalues clamped to [0, max_stiffness] (the force block, the torque
// block and their coupling together: a 6-DoF spring that releases no energy and is not
// stiffer than the device), and the antisymmetric part (-½[τ0]× of a left-trivialised
// torque) is bounded by |τ| <= max_torque. *clamped when a clamp acted. With either
// stiffness bound 0 only the force block is kept (clamped as ClampStiffness does).
bool ClampWrenchStiffness(const double K6[6][6], const SafetyLimits& limits, double out[6][6],
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

// The local model at a pose, unclamped (ForceSafety::Step clamps what it returns):
// F = f0 + K (u - u0) and τ = τ0, or with a 6-DoF model (has_wrench) and an orientation
// (w, x, y, z; null for a device that senses none)
// (F, τ) = (f0, τ0) + K6 (u - u0, log(R R0ᵀ)). No allocation.
void EvaluateLocalModel(const LocalModel& model, const double position_m[3], const double orientation[4],
                        double force_n[3], double torque_nm[3]);

// The envelope one rendered vector (the force, or the torque) goes through each tick, in
// this order: a non-finite v aims at zero (counted as a clamp: no direction to keep);
// |v| <= max_norm; |v - last| <= max_step (the slew limit per tick); a non-finite result
// (which the steps above cannot make from a finite last) is zeroed. v is changed in
// place and last becomes it. Fixed size, no allocation (the servo tick calls it).
struct Limited {
  bool clamped = false;       // the norm limit acted (or v was non-finite)
  bool slew_limited = false;  // the slew limit acted
  bool nonfinite = false;     // the result was zeroed: must never happen
};
Limited LimitVector(double v[3], double max_norm, double max_step, double last[3]);

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
  SafetyLimits limits_;
  // The torque half of Step: τ (model, faded) -> clamped, slew-limited, finite.
  void RenderTorque(double t[3], SafetyOutput* out);
  // A LimitVector verdict into the tick's flags and the counters.
  void Count(const Limited& l, bool* clamped, bool* slewed, std::atomic<uint64_t>& clamps,
             std::atomic<uint64_t>& slews);

  bool has_orientation_;
  bool torque_output_;
  SafetyCounters counters_;
  std::atomic<double> max_force_n_{0.0};
  double last_force_n_[3] = {0.0, 0.0, 0.0};
  double last_torque_nm_[3] = {0.0, 0.0, 0.0};
  double gain_ = 0.0;  // starts at zero: the first model fades in
  std::atomic<bool> fade_out_{false};
  int64_t last_now_us_ = -1;
};

}  // namespace snapthread::device
