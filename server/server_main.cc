// snapthread-server: the solver server process. See server.h for what it does and
// server_params.h for the flags.
//
// Exit codes: 0 after a clean stop (SIGINT/SIGTERM or --duration), 1 when LCM does not
// start (or the --summary file cannot be written), 2 for bad arguments (including a
// scene that does not load).
#include <pthread.h>
#include <sys/stat.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <exception>
#include <fstream>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "scene_dir.h"
#include "server.h"
#include "solvers/registry.h"
#include "server_params.h"
#include "scene/scene.h"

namespace {

constexpr int kExitLcm = 1;
constexpr int kExitUsage = 2;

int Usage(const std::string& message) {
  std::fprintf(stderr, "snapthread-server: %s\n", message.c_str());
  return kExitUsage;
}

// Waits for SIGINT/SIGTERM (blocked in every thread, so only this sigtimedwait sees
// them) or until duration_s has passed (0 = forever). Returns the signal or 0.
int WaitForStop(const sigset_t& signals, double duration_s) {
  timespec start{};
  clock_gettime(CLOCK_MONOTONIC, &start);
  while (true) {
    double wait_s = 0.2;
    if (duration_s > 0.0) {
      timespec now{};
      clock_gettime(CLOCK_MONOTONIC, &now);
      const double elapsed = (now.tv_sec - start.tv_sec) + 1e-9 * (now.tv_nsec - start.tv_nsec);
      if (elapsed >= duration_s) return 0;
      wait_s = std::min(wait_s, duration_s - elapsed);
    }
    timespec timeout{};
    timeout.tv_sec = static_cast<time_t>(wait_s);
    timeout.tv_nsec = static_cast<long>((wait_s - timeout.tv_sec) * 1e9);
    const int sig = sigtimedwait(&signals, nullptr, &timeout);
    if (sig > 0) return sig;
  }
}

}  // namespace

int main(int argc, char** argv) {
  using snapthread::server::ServerParams;
  ServerParams params;
  CLI::App app{"snapthread-server: quasi-static equilibria of an elastic thread, served over "
               "LCM to a haptic device client (force models) and viewers (shape, status)."};
  app.add_option("--scene", params.scene_path, "Scene YAML file (scenes/*.yaml)")->required();
  app.add_option("--session", params.session,
                 "Session name: channel prefix <SESSION>_DEVICE_STATE, ... ([A-Za-z0-9_]+)")
      ->capture_default_str();
  app.add_option("--lcm-url", params.lcm_url,
                 "LCM provider URL (default: $LCM_DEFAULT_URL, else "
                 "udpm://239.255.76.67:7667?ttl=0)");
  app.add_option("--shape-rate-hz", params.shape_rate_hz, "Thread shape rate for viewers, Hz")
      ->capture_default_str();
  app.add_option("--status-rate-hz", params.status_rate_hz, "Solver status rate, Hz")
      ->capture_default_str();
  app.add_option("--method", params.method,
                 "Override the scene's solver: " + snapthread::SolverRegistry::Global().NamesText(" | ", " | "));
  app.add_option("--time-budget-us", params.time_budget_us,
                 "Wall-clock budget per update, microseconds (0 = none; default: the scene's "
                 "solver.time_budget_us). A longer snap spreads over updates (status snapping)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--scene-dir", params.scene_dir,
                 "Directory LOAD_SCENE commands load scenes from, by name only (default: " +
                     snapthread::server::DefaultSceneDir() + ")");
  app.add_option("--load-timeout", params.load_timeout_s,
                 "Seconds a LOAD_SCENE may take before it is abandoned (the current scene "
                 "is served meanwhile)")
      ->capture_default_str();
  app.add_option("--allow-methods", params.allow_methods,
                 "Comma-separated methods SET_METHOD may switch to (default: all: " +
                     snapthread::SolverRegistry::Global().NamesText(",", ",") + ")")
      ->delimiter(',');
  app.add_option("--duration", params.duration_s, "Run time in seconds; 0 = until SIGINT/SIGTERM")
      ->capture_default_str();
  app.add_option("--log-level", params.log_level,
                 "trace | debug | info | warn | error | critical | off")
      ->capture_default_str();
  app.add_option("--summary", params.summary_path,
                 "Write a JSON summary (updates, update_rate_hz, solve_us_p50/p99, snaps, "
                 "dropped_poses, rejected_messages) here at exit");
  app.add_option("--key", params.key_path,
                 "Session key file (default: $SNAPTHREAD_KEY_FILE, else "
                 "$XDG_CONFIG_HOME/snapthread/session.key); must exist (snapthread-keygen "
                 "makes it) unless --create-key");
  app.add_flag("--create-key", params.create_key,
               "Make the session key (mode 0600) when the --key file does not exist");
  app.add_option("--state-dir", params.state_dir,
                 "Checkpoint the scene, method, grasp and state here (>= 5 Hz, atomically); "
                 "restarted with the same directory and --session the server resumes on the "
                 "same branch. Made (mode 0700) when missing. Default: no checkpoints");
  app.add_option("--max-update-hz", params.max_update_hz,
                 "At most this many equilibrium updates per second (0 = the scene's "
                 "solver.max_update_hz; none there: no cap)")
      ->check(CLI::NonNegativeNumber);
  bool no_snap_ahead = false;
  app.add_flag("--no-snap-ahead", no_snap_ahead,
               "Do not send fold boundaries and post-snap models (snap-ahead, docs/snap-ahead.md)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // CLI11's messages name the flag ("--scene is required", "--duration: Value x not
    // in range" ...).
    app.exit(e);
    return kExitUsage;
  }

  params.snap_ahead = !no_snap_ahead;
  std::string error;
  if (!params.IsValid(&error)) return Usage(error);
  {
    const std::string dir =
        params.scene_dir.empty() ? snapthread::server::DefaultSceneDir() : params.scene_dir;
    struct stat info {};
    if (::stat(dir.c_str(), &info) != 0 || !S_ISDIR(info.st_mode)) {
      return Usage("--scene-dir: " + dir + " is not a directory");
    }
  }
  spdlog::set_level(spdlog::level::from_str(params.log_level));
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");

  // Block the stop signals before any thread exists so that every thread inherits the
  // mask and only WaitForStop receives them.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  std::unique_ptr<snapthread::server::Server> server;
  try {
    server = std::make_unique<snapthread::server::Server>(params);
  } catch (const snapthread::auth::KeyFileError& e) {
    return Usage(std::string("--key: ") + e.what());
  } catch (const snapthread::server::CheckpointIoError& e) {
    return Usage(e.what());
  } catch (const snapthread::server::LcmInitError& e) {
    std::fprintf(stderr, "snapthread-server: %s\n", e.what());
    return kExitLcm;
  } catch (const snapthread::SceneError& e) {
    return Usage(std::string("--scene: ") + e.what());
  } catch (const std::invalid_argument& e) {
    return Usage(std::string("--scene: ") + e.what());
  } catch (const std::exception& e) {
    return Usage(std::string("--scene ") + params.scene_path + ": " + e.what());
  }

  server->Start();
  const int sig = WaitForStop(signals, params.duration_s);
  if (sig > 0) spdlog::info("server: signal {}, stopping", sig);
  server->Stop();
  spdlog::info("server: {}", server->FinalReport());
  if (!params.summary_path.empty()) {
    std::ofstream out(params.summary_path);
    out << server->SummaryJson();
    if (!out) {
      spdlog::error("server: could not write the summary to {}", params.summary_path);
      return kExitLcm;
    }
  }
  return 0;
}
