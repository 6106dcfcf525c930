// snapthread-server: the solver server process. See server.h for what it does and
// server_params.h for the flags.
//
// SIGHUP reloads the keys (the root file after snapthread-keygen --rotate, FILE.revoked).
//
// Exit codes (app/exit_codes.h): 0 after a clean stop (SIGINT/SIGTERM or --duration), 1
// when LCM does not start (or the --summary file cannot be written), 2 for bad arguments
// (including a scene that does not load).
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>

#include <exception>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "app/command_line.h"
#include "app/common_flags.h"
#include "app/exit_codes.h"
#include "app/stop_signals.h"
#include "auth/credential.h"
#include "auth/revocation_list.h"
#include "scene/scene.h"
#include "scene_dir.h"
#include "server.h"
#include "server_params.h"
#include "solvers/registry.h"

namespace snapthread::server {
namespace {

constexpr const char* kProgram = "snapthread-server";
constexpr const char* kDescription =
    "snapthread-server: quasi-static equilibria of an elastic thread, served over LCM to a "
    "haptic device client (force models) and viewers (shape, status).";

struct ServerFlags {
  ServerParams params;
  app::CommonFlags common;  // --session, --lcm-url, --key, --log-level
  bool no_snap_ahead = false;
};

// The registered solver methods, joined by `separator`.
std::string MethodNames(const char* separator) {
  return SolverRegistry::Global().NamesText(separator, separator);
}

// What the server solves and how: the scene, the methods, the budgets and the rates.
void AddSolveFlags(CLI::App* cli, ServerParams* p) {
  cli->add_option("--scene", p->scene_path, "Scene YAML file (scenes/*.yaml)")->required();
  cli->add_option("--shape-rate-hz", p->shape_rate_hz, "Thread shape rate for viewers, Hz")
      ->capture_default_str();
  cli->add_option("--status-rate-hz", p->status_rate_hz, "Solver status rate, Hz")->capture_default_str();
  cli->add_option("--method", p->method, "Override the scene's solver: " + MethodNames(" | "));
  cli->add_option("--time-budget-us", p->time_budget_us,
                  "Wall-clock budget per update, microseconds (0 = none; default: the scene's "
                  "solver.time_budget_us). A longer snap spreads over updates (status snapping)")
      ->check(CLI::NonNegativeNumber);
  cli->add_option("--max-update-hz", p->max_update_hz,
                  "At most this many equilibrium updates per second (0 = the scene's "
                  "solver.max_update_hz; none there: no cap)")
      ->check(CLI::NonNegativeNumber);
}

// What the COMMAND channel may ask for: LOAD_SCENE's directory and time, SET_METHOD's methods.
void AddCommandFlags(CLI::App* cli, ServerParams* p) {
  cli->add_option("--scene-dir", p->scene_dir,
                  "Directory LOAD_SCENE commands load scenes from, by name only (default: " +
                      DefaultSceneDir() + ")");
  cli->add_option("--load-timeout", p->load_timeout_s,
                  "Seconds a LOAD_SCENE may take before it is abandoned (the current scene "
                  "is served meanwhile)")
      ->capture_default_str();
  cli->add_option("--allow-methods", p->allow_methods,
                  "Comma-separated methods SET_METHOD may switch to (default: all: " + MethodNames(",") + ")")
      ->delimiter(',');
}

// The run: how long, the key's creation, the checkpoints, the summary, snap-ahead.
void AddRunFlags(CLI::App* cli, ServerFlags* f) {
  ServerParams* p = &f->params;
  cli->add_option("--duration", p->duration_s, "Run time in seconds; 0 = until SIGINT/SIGTERM")
      ->capture_default_str();
  cli->add_option("--summary", p->summary_path,
                  "Write a JSON summary (updates, update_rate_hz, solve_us_p50/p99, snaps, "
                  "dropped_poses, rejected_messages) here at exit");
  cli->add_flag("--create-key", p->create_key, "Make the root key (mode 0600) when the --key file does not exist");
  cli->add_option("--key-grace-s", p->key_grace_s,
                  "Seconds the previous root key stays accepted after a reload (SIGHUP) finds a "
                  "rotated --key (snapthread-keygen --rotate), or after a start that finds FILE.previous")
      ->capture_default_str();
  cli->add_option("--state-dir", p->state_dir,
                  "Checkpoint the scene, method, grasp and state here (>= 5 Hz, atomically); "
                  "restarted with the same directory and --session the server resumes on the "
                  "same branch. Made (mode 0700) when missing. Default: no checkpoints");
  cli->add_flag("--no-snap-ahead", f->no_snap_ahead,
                "Do not send fold boundaries and post-snap models (snap-ahead, docs/snap-ahead.md)");
}

void AddServerFlags(CLI::App* cli, ServerFlags* f) {
  AddSolveFlags(cli, &f->params);
  app::CommonFlagSet common;
  common.log_level = true;
  common.encrypt = true;
  common.key_note = "; must exist (snapthread-keygen makes it) unless --create-key";
  app::AddCommonFlags(cli, &f->common, common);
  AddCommandFlags(cli, &f->params);
  AddRunFlags(cli, f);
}

// The parsed flags as the server's parameters.
ServerParams Params(const ServerFlags& f) {
  ServerParams params = f.params;
  params.session = f.common.session;
  params.lcm_url = f.common.lcm_url;  // resolved by the server (ServerParams::lcm_url)
  params.key_path = f.common.key_path;
  params.encrypt = f.common.encrypt;
  params.log_level = f.common.log_level;
  params.snap_ahead = !f.no_snap_ahead;
  return params;
}

// The parameters' checks and --scene-dir's directory: the usage exit code naming the flag.
std::optional<int> CheckParams(const ServerParams& params) {
  std::string error;
  if (!params.IsValid(&error)) return app::Fail(kProgram, app::kExitUsage, error);
  const std::string dir = params.scene_dir.empty() ? DefaultSceneDir() : params.scene_dir;
  struct stat info {};
  if (::stat(dir.c_str(), &info) != 0 || !S_ISDIR(info.st_mode)) {
    return app::Fail(kProgram, app::kExitUsage, "--scene-dir: " + dir + " is not a directory");
  }
  return std::nullopt;
}

// The server (key, scene, checkpoints, LCM), or the exit code naming what failed.
std::optional<int> MakeServer(const ServerParams& params, std::unique_ptr<Server>* out) {
  const auto usage = [](const std::string& message) { return app::Fail(kProgram, app::kExitUsage, message); };
  try {
    *out = std::make_unique<Server>(params);
  } catch (const auth::KeyFileError& e) {
    return usage(std::string("--key: ") + e.what());
  } catch (const auth::CredentialError& e) {
    return usage(std::string("--key: ") + e.what());
  } catch (const auth::RevocationListError& e) {
    return usage(std::string("--key: ") + e.what());
  } catch (const CheckpointIoError& e) {
    return usage(e.what());
  } catch (const LcmInitError& e) {
    return app::Fail(kProgram, app::kExitFailure, e.what());
  } catch (const SceneError& e) {
    return usage(std::string("--scene: ") + e.what());
  } catch (const std::invalid_argument& e) {
    return usage(std::string("--scene: ") + e.what());
  } catch (const std::exception& e) {
    return usage(std::string("--scene ") + params.scene_path + ": " + e.what());
  }
  return std::nullopt;
}

// SIGHUP, taken synchronously like the stop signals: blocked here, before any thread, so
// that every thread inherits the mask and only RunUntilStop sees it.
sigset_t BlockReloadSignal() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  return set;
}

// Until SIGINT/SIGTERM or the duration: each SIGHUP asks the server to reload its keys
// (applied by its receive thread). Returns the stop signal, 0 when the duration ended.
int RunUntilStop(app::StopSignals* stop, const sigset_t& reload, double duration_s, Server* server) {
  constexpr double kSliceS = 0.2;  // how late a reload may be applied
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration_s);
  while (true) {
    double slice = kSliceS;
    if (duration_s > 0.0) {
      const double left = std::chrono::duration<double>(end - std::chrono::steady_clock::now()).count();
      if (left <= 0.0) return 0;
      slice = std::min(slice, left);
    }
    if (const int sig = stop->Wait(slice); sig > 0) return sig;
    const timespec zero{};
    if (sigtimedwait(&reload, nullptr, &zero) == SIGHUP) {
      spdlog::info("server: SIGHUP, reloading the keys");
      server->RequestReload();
    }
  }
}

// --summary: the run's JSON; kExitFailure when it cannot be written.
int WriteSummary(const ServerParams& params, const Server& server) {
  if (params.summary_path.empty()) return app::kExitOk;
  std::ofstream out(params.summary_path);
  out << server.SummaryJson();
  if (!out) {
    spdlog::error("server: could not write the summary to {}", params.summary_path);
    return app::kExitFailure;
  }
  return app::kExitOk;
}

}  // namespace
}  // namespace snapthread::server

int main(int argc, char** argv) {
  namespace app = snapthread::app;
  namespace server = snapthread::server;
  server::ServerFlags flags;
  CLI::App cli{server::kDescription};
  server::AddServerFlags(&cli, &flags);
  if (auto code = app::ParseCommandLine(cli, argc, argv, app::kExitUsage)) return *code;
  if (auto code = app::CheckCommonFlags(flags.common, server::kProgram, app::kExitUsage)) return *code;
  const server::ServerParams params = server::Params(flags);
  if (auto code = server::CheckParams(params)) return *code;
  spdlog::set_level(spdlog::level::from_str(params.log_level));
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");

  app::StopSignals stop;  // before the server's threads (and LCM's): they inherit the mask
  const sigset_t reload = server::BlockReloadSignal();
  std::unique_ptr<server::Server> running;
  if (auto code = server::MakeServer(params, &running)) return *code;
  running->Start();
  if (const int sig = server::RunUntilStop(&stop, reload, params.duration_s, running.get()); sig > 0) {
    spdlog::info("server: signal {}, stopping", sig);
  }
  running->Stop();
  spdlog::info("server: {}", running->FinalReport());
  return server::WriteSummary(params, *running);
}
