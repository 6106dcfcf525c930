// LCM channel names of one snapthread session. Several sessions share one LAN by
// prefixing every channel with the session name (shared/DESIGN.md "Messages").
#pragma once

#include <cstddef>
#include <string>

namespace snapthread::transport {

inline constexpr const char* kDefaultSession = "SNAPTHREAD";

struct Channels {
  // Throws std::invalid_argument when `session` is empty or not [A-Za-z0-9_]+ (user
  // input, checked once at start-up).
  explicit Channels(const std::string& session = kDefaultSession);

  std::string session;
  std::string device_state;   // <SESSION>_DEVICE_STATE   device_state_t
  std::string force_model;    // <SESSION>_FORCE_MODEL    force_model_t
  std::string shape;          // <SESSION>_SHAPE          thread_shape_t
  std::string solver_status;  // <SESSION>_SOLVER_STATUS  solver_status_t
  std::string device_status;  // <SESSION>_DEVICE_STATUS  device_status_t
  std::string command;        // <SESSION>_COMMAND        command_t
};

// LCM refuses channel names longer than 63 bytes (at publish time, sending nothing);
// the longest suffix, "_SOLVER_STATUS" / "_DEVICE_STATUS", takes 14 of them.
inline constexpr size_t kMaxSessionNameLength = 63 - 14;

// True when `session` matches [A-Za-z0-9_]+ and has at most kMaxSessionNameLength
// characters, so every channel of the session is a name LCM accepts.
bool IsValidSessionName(const std::string& session);

}  // namespace snapthread::transport
