// Parameters of one snapthread-server process (Drake-style documented parameter struct,
// cf. drake/lcm/drake_lcm_params.h): where to talk, which session, which scene, how often
// to publish. Filled from the command line by server_main.cc or directly by tests.
#pragma once

#include <cstddef>
#include <string>

#include "messages/channels.h"

namespace snapthread::server {

// LCM channel names are at most 63 bytes; the longest channel suffix is 14 bytes.
inline constexpr size_t kMaxSessionLength = transport::kMaxSessionNameLength;

struct ServerParams {
  // LCM provider URL. Empty: the environment's LCM_DEFAULT_URL if set, else the loopback
  // multicast default udpm://239.255.76.67:7667?ttl=0 (transport::ResolveLcmUrl).
  std::string lcm_url;
  // Channel prefix: the server listens on <session>_DEVICE_STATE and <session>_COMMAND
  // and publishes <session>_FORCE_MODEL, _SHAPE and _SOLVER_STATUS. [A-Za-z0-9_]+,
  // at most kMaxSessionLength characters.
  std::string session = "SNAPTHREAD";
  // Scene YAML file (required).
  std::string scene_path;
  // thread_shape_t rate for viewers, Hz (> 0). 60 Hz matches a display refresh.
  double shape_rate_hz = 60.0;
  // solver_status_t rate, Hz (> 0).
  double status_rate_hz = 10.0;
  // Solver method override: "" (use the scene's), "newton", "newton-ls" or
  // "higher-order". An override survives RESET and LOAD_SCENE until SET_METHOD.
  std::string method;
  // spdlog level name: trace, debug, info, warn, error, critical, off.
  std::string log_level = "info";
  // Run time in seconds for the process (server_main.cc); 0 = until SIGINT/SIGTERM.
  double duration_s = 0.0;
  // Where to write the end-of-run JSON summary; empty = none.
  std::string summary_path;
  // The session key file (--key): "" = $SNAPTHREAD_KEY_FILE, else the XDG default
  // (auth/key_file.h). The server creates it when it does not exist.
  std::string key_path;

  // False with a message naming the offending field (as a command-line flag) when
  // invalid. Does not touch the file system (the scene is checked when loaded).
  bool IsValid(std::string* error) const;
};

}  // namespace snapthread::server
