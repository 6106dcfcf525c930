// Parameters of one snapthread-server process (Drake-style documented parameter struct,
// cf. drake/lcm/drake_lcm_params.h): where to talk, which session, which scene, how often
// to publish. Filled from the command line by server_main.cc or directly by tests.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "messages/channels.h"

namespace snapthread::server {

// LCM channel names are at most 63 bytes; the longest channel suffix is 14 bytes.
inline constexpr size_t kMaxSessionLength = messages::kMaxSessionNameLength;
// The longest --key-grace-s: a year.
inline constexpr double kMaxKeyGraceS = 365.0 * 24 * 3600;

struct ServerParams {
  // LCM provider URL. Empty: the environment's LCM_DEFAULT_URL if set, else the loopback
  // multicast default udpm://239.255.76.67:7667?ttl=0 (messages::ResolveLcmUrl).
  std::string lcm_url;
  // Channel prefix: the server listens on <session>_DEVICE_STATE and <session>_COMMAND
  // and publishes <session>_FORCE_MODEL, _SHAPE and _SOLVER_STATUS. [A-Za-z0-9_]+,
  // at most kMaxSessionLength characters.
  std::string session = "SNAPTHREAD";
  // Scene YAML file (required). The operator's command line may name any path; the
  // COMMAND channel may not (scene_dir).
  std::string scene_path;
  // Where LOAD_SCENE finds scenes, by name only (scene_dir.h). Empty: the project's
  // scenes/ directory (DefaultSceneDir()).
  std::string scene_dir;
  // A LOAD_SCENE that takes longer than this (read, parse, build the tracker) is
  // abandoned and reported; the current scene is served meanwhile. Seconds, > 0.
  double load_timeout_s = 5.0;
  // Methods SET_METHOD may switch to; empty = every registered method. Each name must
  // be registered (checked by IsValid); --method must be one of them.
  std::vector<std::string> allow_methods;
  // thread_shape_t rate for viewers, Hz (> 0). 60 Hz matches a display refresh.
  double shape_rate_hz = 60.0;
  // solver_status_t rate, Hz (> 0).
  double status_rate_hz = 10.0;
  // Solver method override: "" (use the scene's), "newton", "newton-ls" or
  // "higher-order". An override survives RESET and LOAD_SCENE until SET_METHOD.
  std::string method;
  // Wall-clock budget per update, microseconds (--time-budget-us): < 0 = the scene's
  // solver.time_budget_us, 0 = none. Like --method it survives RESET and LOAD_SCENE. A
  // snap that outlasts it spreads over updates, published as STATUS_SNAPPING with the
  // snap's current force and K = 0 (docs/time-budget.md).
  double time_budget_us = -1.0;
  // spdlog level name: trace, debug, info, warn, error, critical, off.
  std::string log_level = "info";
  // Run time in seconds for the process (server_main.cc); 0 = until SIGINT/SIGTERM.
  double duration_s = 0.0;
  // Where to write the end-of-run JSON summary; empty = none.
  std::string summary_path;
  // The root key file (--key): "" = $SNAPTHREAD_KEY_FILE, else the XDG default
  // (auth/key_file.h). It must exist unless create_key. FILE.previous (a rotation) and
  // FILE.revoked (revocations) beside it are read at the start and on reload.
  std::string key_path;
  // --create-key: make the key (mode 0600) when the file does not exist. Without it a
  // missing key is refused (a typo in --key must not give a new key).
  bool create_key = false;
  // --key-grace-s: after a reload (SIGHUP) finds a new root key, or at a start that finds
  // FILE.previous, messages made under the previous root are accepted for this many
  // seconds (a session rides through a rotation), then refused as grace-over. Finite, >= 0.
  double key_grace_s = 60.0;
  bool encrypt = false;  // --encrypt: seal what the server publishes (docs/security.md)
  // Where the server checkpoints the scene, method, grasp and state (--state-dir; "" =
  // no checkpoints). Restarted with the same directory and session it resumes on the
  // same branch (server/checkpoint.h). Made (mode 0700) when missing.
  std::string state_dir;
  // At most this many equilibrium updates per second (--max-update-hz): > 0 caps
  // the solve rate (the newest pose waits for its slot; large models, tests); 0 = the
  // scene's solver.max_update_hz (0 there too: no cap).
  double max_update_hz = 0.0;
  // Snap-ahead (server/fold_boundary.h): near a fold send the fold boundary and
  // the post-snap model with the force model. --no-snap-ahead turns it off.
  bool snap_ahead = true;
  // Checkpoints per second while the state changes (>= 5); not a flag.
  double checkpoint_rate_hz = 20.0;

  // False with a message naming the offending field (as a command-line flag) when
  // invalid. Does not touch the file system (the scene is checked when loaded).
  bool IsValid(std::string* error) const;
  // SET_METHOD may switch to `method` (allow_methods empty or naming it).
  bool IsMethodAllowed(const std::string& method) const;
};

}  // namespace snapthread::server
