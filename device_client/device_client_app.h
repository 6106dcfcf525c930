// snapthread-device as a library entry point: command-line options and the process
// wiring (scene, backend, LcmDeviceTransport, DeviceClient, signals, summary). The
// client itself - servo loop, model receiver, io - is DeviceClient (device_client.h).
#pragma once

#include <optional>
#include <string>

#include "app/common_flags.h"
#include "app/stop_signals.h"
#include "reload_signal.h"

namespace snapthread::device {

struct DeviceClientOptions {
  std::string backend = "virtual-hand";  // sim-path | virtual-hand | phantom | delta
  std::string scene_file;                // scene YAML: DeviceMapping + grasp path
  std::string grasp;                     // scene grasp to hold (--grasp); "" = the first
  std::string path_csv;                  // alternative scripted path, metres
  app::CommonFlags common;               // --session, --lcm-url, --key, --log-level
  double key_grace_s = 60.0;             // previous key accepted this long after a reload
  double duration_s = 0.0;               // 0 = until SIGINT / SIGTERM
  double rate_hz = 1000.0;
  int publish_divisor = 1;               // publish every k-th pose
  double model_timeout_ms = 50.0;
  double fade_ms = 100.0;
  double speed_m_per_s = 0.02;           // scripted path speed
  double angular_speed_deg_per_s = 45.0; // scripted path turning speed (a rod scene's roll)
  // Torque output (devices with a motorised wrist, and sim-path): safety.h.
  double max_torque_nm = 0.05;
  double max_torque_rate_nm_per_s = 20.0;
  double max_torque_stiffness_nm_per_rad = 0.1;
  bool realtime = true;                  // --no-rt turns off SCHED_FIFO / mlockall
  bool snap_ahead = true;                // --no-snap-ahead: never switch at a fold boundary
  std::string trace_file;                // CSV, empty = none
  int trace_divisor = 1;
  std::string summary_file;              // JSON at exit, empty = none
  // --sim-render-file: a simulated backend runs its render thread ("firmware",
  // sim_renderer.h) and publishes what it renders in this memory-mapped file.
  std::string sim_render_file;
};

// Exit codes of snapthread-device (app/exit_codes.h): app::kExitOk, app::kExitFailure
// when the device, LCM or the --summary file fails, app::kExitUsage for bad arguments.

// Parses argv into *options. nullopt: go on; otherwise the exit code (app::kExitOk after
// --help, app::kExitUsage with a message on stderr naming the argument).
std::optional<int> ParseDeviceClientArgs(int argc, char** argv, DeviceClientOptions* options);

// Runs the client until the duration elapses or `stop` sees SIGINT / SIGTERM (the main
// thread waits on it; the servo thread never does); returns an exit code. On each SIGHUP
// `reload` sees, the --key file is loaded again (device_keys.h). `stop` and `reload` must
// exist before any thread does (app/stop_signals.h).
int RunDeviceClient(const DeviceClientOptions& options, app::StopSignals* stop,
                    ReloadSignal* reload = nullptr);

}  // namespace snapthread::device
