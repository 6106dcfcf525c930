// Helpers shared by the bench's charts (internal to tools/bench/).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

#include "bench.h"

namespace snapthread {

using Clock = std::chrono::steady_clock;

inline double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

inline std::string BudgetText(int budget) { return budget == 0 ? "inf" : std::to_string(budget); }

std::string Sci(double v, int digits = 2);

// Relative rms force error of a trace against a reference of the same rows.
double RelativeRmsForceError(const std::vector<SweepRow>& trace, const std::vector<SweepRow>& ref, double scale);

double ForceScaleOf(const Scene& scene);

// The scene solved with `method`, `cutoff` and an iteration budget (0 = unlimited).
Scene WithSolver(const Scene& scene, const std::string& method, double cutoff, int budget);

// Child processes of the service and flood charts (service.cc).
// The whole file ("" when it cannot be read).
std::string ReadFile(const std::string& path);
// Starts argv[0] with stdout and stderr into `log`; returns the pid or -1.
pid_t Spawn(const std::vector<std::string>& args, const std::string& log);
// Waits for pid up to `timeout_s`; returns its exit status, or -1 after killing it.
int WaitFor(pid_t pid, double timeout_s);

// One server + device session of the service and flood charts: its files and binaries.
struct ServiceSession {
  std::string server_bin, device_bin;  // --bin-dir's snapthread-server and snapthread-device
  std::string scene_file;              // <scenes_dir>/<scene>.yaml
  std::string session;                 // the LCM session name
  std::string base;                    // <work_dir>/<session>: prefix of the run's logs and summaries
  std::string key_path;                // the session key both sign with
  std::string lcm_url;
  double duration_s = 0.0;             // the device's run time
};
// Fills the binaries, scene file and base of `s` (work_dir is made); false with *error when
// a binary is missing.
bool PrepareServiceSession(const std::string& bin_dir, const std::string& scenes_dir, const std::string& scene,
                           const std::string& work_dir, ServiceSession* s, std::string* error);
// A new session key (mode 0600) at `path`; false with *error.
bool WriteSessionKey(const std::string& path, std::string* error);
// Starts the server (its --duration only a safety net past the device's) and waits until it
// serves (its "server: session" line); the pid, or -1 with *error (the server stopped).
pid_t StartServer(const ServiceSession& s, std::string* error);
// The device's command line both charts share (virtual-hand, 1 kHz, every pose published,
// a JSON summary at <base>_device.json); the caller appends its own flags.
std::vector<std::string> DeviceArgs(const ServiceSession& s);
// Stops the server after the device ended with `device_rc`: "" when both exited 0, else
// what each did and where the logs are.
std::string StopServer(pid_t server, int device_rc, const ServiceSession& s);

}  // namespace snapthread
