#include "safety_limits.h"

#include <algorithm>
#include <cmath>

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

}  // namespace snapthread::device
