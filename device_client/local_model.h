// The device's local model (shared/DESIGN.md "Forces and the device's local model"): the
// server's force model as the servo tick uses it, built from the message and evaluated.
//  * PrepareModel, off the servo thread, when a force model ARRIVES: refuses non-finite
//    or malformed models, turns STATUS_INVALID into a zero-force model, symmetrises K
//    and clamps its stiffness to the stable range (stiffness_clamp.h), and checks the
//    fold of a snap-ahead model (PrepareFold). The servo tick then only evaluates.
//  * EvaluateLocalModel, on the servo thread: F = f0 + K (u - u0) at the hand's pose,
//    before the safety stage (safety.h) fades, clamps and slew-limits it.
//  * A full-pose grasp (the rod: force_model_t.has_wrench) is a 6-DoF local model about
//    the pose (u0, R0):  (F, τ) = (f0, τ0) + K6 (u - u0, r),  r = log(R R0ᵀ) from the
//    device's quaternion, with a stiffness clamp on K6 (ClampWrenchStiffness).
#pragma once

#include <cstdint>
#include <string>

#include "safety_limits.h"
#include "snapthread/force_model_t.hpp"

namespace snapthread::device {

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
  // Snap-ahead (snap_ahead.h): the fold boundary and the post-snap model, checked
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

enum class ModelVerdict {
  kAccepted,          // usable as sent (K symmetrised)
  kStiffnessClamped,  // usable, K's stiffness was clamped to [0, max]
  kInvalidStatus,     // STATUS_INVALID: usable as a zero-force model
  kRejected,          // not usable: never reaches the device
};

// Off the servo thread. Fills *out unless the verdict is kRejected (reason in *why). A
// model with a bad fold (not finite, not a unit normal, no positive id) is refused whole,
// so a bad fold never reaches the servo.
ModelVerdict PrepareModel(const force_model_t& msg, int64_t receive_us,
                          const SafetyLimits& limits, LocalModel* out, std::string* why);

// The local model at a pose, unclamped (ForceSafety::Step clamps what it returns):
// F = f0 + K (u - u0) and τ = τ0, or with a 6-DoF model (has_wrench) and an orientation
// (w, x, y, z; null for a device that senses none)
// (F, τ) = (f0, τ0) + K6 (u - u0, log(R R0ᵀ)). No allocation.
void EvaluateLocalModel(const LocalModel& model, const double position_m[3], const double orientation[4],
                        double force_n[3], double torque_nm[3]);

}  // namespace snapthread::device
