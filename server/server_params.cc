#include "server_params.h"

#include <algorithm>
#include <cmath>

#include "solvers/registry.h"
#include "messages/channels.h"

namespace snapthread::server {
namespace {

bool Fail(std::string* error, const std::string& message) {
  if (error != nullptr) *error = message;
  return false;
}

bool IsKnownLogLevel(const std::string& level) {
  for (const char* name : {"trace", "debug", "info", "warn", "warning", "error", "err",
                           "critical", "off"}) {
    if (level == name) return true;
  }
  return false;
}

}  // namespace

bool ServerParams::IsValid(std::string* error) const {
  if (scene_path.empty()) return Fail(error, "--scene: a scene file is required");
  if (!messages::IsValidSessionName(session)) {
    return Fail(error, "--session: '" + session + "' is not a valid session name ([A-Za-z0-9_]+)");
  }
  // LCM refuses channel names longer than 63 bytes at publish time (logging "channel
  // name too long" for every message, sending nothing); the longest suffix is
  // "_SOLVER_STATUS" / "_DEVICE_STATUS" (14 bytes).
  if (session.size() > kMaxSessionLength) {
    return Fail(error, "--session: '" + session + "' is longer than " +
                           std::to_string(kMaxSessionLength) +
                           " characters (LCM channel names are at most 63 bytes)");
  }
  // A rate of 0 would make the publish period infinite; 10 kHz is far above any viewer.
  if (!std::isfinite(shape_rate_hz) || shape_rate_hz <= 0.0 || shape_rate_hz > 10000.0) {
    return Fail(error, "--shape-rate-hz: must be in (0, 10000], got " + std::to_string(shape_rate_hz));
  }
  if (!std::isfinite(status_rate_hz) || status_rate_hz <= 0.0 || status_rate_hz > 1000.0) {
    return Fail(error, "--status-rate-hz: must be in (0, 1000], got " + std::to_string(status_rate_hz));
  }
  if (!std::isfinite(time_budget_us)) {
    return Fail(error, "--time-budget-us: must be a finite number (>= 0; omit it for the scene's)");
  }
  // Bounded so that now + grace stays far from int64's end (a year is beyond any rotation).
  if (!std::isfinite(key_grace_s) || key_grace_s < 0.0 || key_grace_s > kMaxKeyGraceS) {
    return Fail(error, "--key-grace-s: must be in [0, " + std::to_string(static_cast<int64_t>(kMaxKeyGraceS)) +
                           "] seconds, got " + std::to_string(key_grace_s));
  }
  if (!method.empty()) {
    if (SolverRegistry::Global().Find(method) == nullptr) {
      return Fail(error, "--method: unknown method '" + method + "' (expected " +
                             SolverRegistry::Global().NamesText(", ", " or ") + ")");
    }
  }
  for (const std::string& name : allow_methods) {
    if (SolverRegistry::Global().Find(name) == nullptr) {
      return Fail(error, "--allow-methods: unknown method '" + name + "' (expected " +
                             SolverRegistry::Global().NamesText(", ", " or ") + ")");
    }
  }
  if (!method.empty() && !IsMethodAllowed(method)) {
    return Fail(error, "--method: '" + method + "' is not in --allow-methods");
  }
  if (!std::isfinite(load_timeout_s) || load_timeout_s <= 0.0 || load_timeout_s > 3600.0) {
    return Fail(error, "--load-timeout: must be in (0, 3600] seconds, got " +
                           std::to_string(load_timeout_s));
  }
  if (!std::isfinite(checkpoint_rate_hz) || checkpoint_rate_hz < 5.0 || checkpoint_rate_hz > 1000.0) {
    return Fail(error, "checkpoint rate: must be in [5, 1000] Hz, got " +
                           std::to_string(checkpoint_rate_hz));
  }
  if (!std::isfinite(max_update_hz) || max_update_hz < 0.0 || max_update_hz > 100000.0) {
    return Fail(error, "--max-update-hz: must be in [0, 100000] (0 = the scene's), got " +
                           std::to_string(max_update_hz));
  }
  if (!IsKnownLogLevel(log_level)) {
    return Fail(error, "--log-level: unknown level '" + log_level +
                           "' (expected trace, debug, info, warn, error, critical or off)");
  }
  if (!std::isfinite(duration_s) || duration_s < 0.0) {
    return Fail(error, "--duration: must be >= 0 seconds, got " + std::to_string(duration_s));
  }
  return true;
}

bool ServerParams::IsMethodAllowed(const std::string& name) const {
  return allow_methods.empty() ||
         std::find(allow_methods.begin(), allow_methods.end(), name) != allow_methods.end();
}

}  // namespace snapthread::server
