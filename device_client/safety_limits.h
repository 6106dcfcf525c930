// The limits the device client's safety layer enforces (shared/DESIGN.md "Forces and the
// device's local model"): the force and torque bounds, their slew limits, the stiffness a
// haptic loop renders stably, the model watchdog's timeout and fade, and the workspace.
// Both halves of the safety layer read them: the local model's preparation clamps the
// stiffness (local_model.h), the servo tick bounds the output (safety.h).
#pragma once

#include <string>

#include "haptic_device.h"
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

}  // namespace snapthread::device
