#include "device_client_app.h"

#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <thread>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "auth/key_file.h"
#include "auth/session_key.h"
#include "device_client.h"
#include "device_factory.h"
#include "lcm_transport.h"
#include "messages/channels.h"
#include "messages/lcm_url.h"
#include "realtime/clock.h"
#include "safety.h"
#include "scene/scene.h"
#include "scripted_path.h"

namespace snapthread::device {
namespace {

// Set by the SIGINT/SIGTERM handler (async-signal-safe: a lock-free atomic store).
std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free);

void OnSignal(int) { g_stop_requested.store(true); }

void InstallSignalHandlers() {
  struct sigaction sa {};
  sa.sa_handler = &OnSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

double Seconds(int64_t us) { return 1e-6 * static_cast<double>(us); }

void LogSummary(const DeviceClientSummary& s) {
  spdlog::info("device: done after {:.2f} s: {} ticks ({:.1f} Hz), lateness p50/p99/max "
               "{:.0f}/{:.0f}/{:.0f} us, round trip p50/p99 {:.0f}/{:.0f} us, models {} "
               "received / {} rejected, poses rejected {}, force clamps {}, stiffness clamps {}, "
               "slew limits {}, fade ticks {}, snaps felt {}, max |F| {:.3f} N, non-finite "
               "outputs {}, overruns {}",
               s.duration_s, s.ticks, s.tick_rate_hz, s.lateness_us.p50, s.lateness_us.p99,
               s.lateness_us_max, s.round_trip_us.p50, s.round_trip_us.p99, s.models_received,
               s.models_rejected, s.poses_rejected, s.force_clamps, s.stiffness_clamps,
               s.slew_limits, s.fade_ticks, s.snaps_felt, s.max_force_n, s.nonfinite_outputs,
               s.overruns);
}

bool WriteSummaryJson(const std::string& path, const DeviceClientOptions& o,
                      const DeviceClientSummary& s) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return false;
  auto u = [](uint64_t v) { return static_cast<unsigned long long>(v); };
  std::fprintf(
      f,
      "{\n  \"backend\": \"%s\",\n  \"session\": \"%s\",\n  \"duration_s\": %.6f,\n"
      "  \"ticks\": %llu,\n  \"tick_rate_hz\": %.3f,\n"
      "  \"lateness_us_p50\": %.1f,\n  \"lateness_us_p99\": %.1f,\n  \"lateness_us_max\": %.1f,\n"
      "  \"round_trip_us_p50\": %.1f,\n  \"round_trip_us_p99\": %.1f,\n"
      "  \"models_received\": %llu,\n  \"models_rejected\": %llu,\n  \"invalid_models\": %llu,\n"
      "  \"poses_rejected\": %llu,\n  \"force_clamps\": %llu,\n  \"stiffness_clamps\": %llu,\n"
      "  \"slew_limits\": %llu,\n  \"fade_ticks\": %llu,\n  \"snaps_felt\": %llu,\n"
      "  \"snap_ahead_switches\": %llu,\n"
      "  \"max_force_n\": %.6f,\n  \"final_force_n\": %.6f,\n  \"nonfinite_outputs\": %llu,\n  \"overruns\": %llu,\n"
      "  \"read_failures\": %llu,\n  \"pose_ring_drops\": %llu,\n  \"trace_ring_drops\": %llu,\n"
      "  \"invalid_poses_unpublished\": %llu,\n  \"torque_clamps\": %llu,\n"
      "  \"torque_slew_limits\": %llu,\n  \"wrench_models\": %llu,\n"
      "  \"statuses_accepted\": %llu,\n  \"statuses_rejected\": %llu,\n"
      "  \"statuses_superseded\": %llu,\n  \"statuses_oversized\": %llu,\n  \"realtime\": %s\n}\n",
      o.backend.c_str(), o.session.c_str(), s.duration_s, u(s.ticks), s.tick_rate_hz,
      s.lateness_us.p50, s.lateness_us.p99, s.lateness_us_max, s.round_trip_us.p50,
      s.round_trip_us.p99, u(s.models_received), u(s.models_rejected), u(s.invalid_models),
      u(s.poses_rejected), u(s.force_clamps), u(s.stiffness_clamps), u(s.slew_limits),
      u(s.fade_ticks), u(s.snaps_felt), u(s.snap_ahead_switches), s.max_force_n, s.final_force_n, u(s.nonfinite_outputs), u(s.overruns),
      u(s.read_failures), u(s.pose_ring_drops), u(s.trace_ring_drops),
      u(s.invalid_poses_unpublished), u(s.torque_clamps), u(s.torque_slew_limits), u(s.wrench_models),
      u(s.statuses_accepted), u(s.statuses_rejected), u(s.statuses_superseded),
      u(s.statuses_oversized), s.realtime ? "true" : "false");
  std::fclose(f);
  return true;
}

// "Go on" from a step that may end the program with an exit code.
constexpr int kContinue = -1;

void PrintError(const std::string& what) { std::fprintf(stderr, "snapthread-device: %s\n", what.c_str()); }

// What RunDeviceClient sets up before the transport: the key, the scene and its grasp,
// the backend (built, not open).
struct ClientSetup {
  std::optional<auth::SessionKey> key;
  std::optional<Scene> scene;
  int grasp = 0;
  BackendConfig config;
  Backend backend;
};

// The session name and the ranges CLI11's checks let through ("nan" fails no
// comparison): kExitBadArguments naming the flag, or kContinue.
int CheckOptions(const DeviceClientOptions& o) {
  if (!messages::IsValidSessionName(o.session)) {
    std::fprintf(stderr, "snapthread-device: --session '%s': expected [A-Za-z0-9_]+\n",
                 o.session.c_str());
    return kExitBadArguments;
  }
  const struct {
    const char* flag;
    bool ok;
  } ranges[] = {
      {"--rate-hz", o.rate_hz >= 100.0 && o.rate_hz <= 10000.0},
      {"--publish-divisor", o.publish_divisor >= 1},
      {"--trace-divisor", o.trace_divisor >= 1},
      {"--model-timeout-ms", o.model_timeout_ms > 0.0 && std::isfinite(o.model_timeout_ms)},
      {"--fade-ms", o.fade_ms > 0.0 && std::isfinite(o.fade_ms)},
      {"--speed-m-per-s", o.speed_m_per_s > 0.0 && std::isfinite(o.speed_m_per_s)},
      {"--duration", o.duration_s >= 0.0 && std::isfinite(o.duration_s)},
      {"--angular-speed-deg-per-s", o.angular_speed_deg_per_s > 0.0 && std::isfinite(o.angular_speed_deg_per_s)},
      {"--max-torque-nm", o.max_torque_nm >= 0.0 && std::isfinite(o.max_torque_nm)},
      {"--max-torque-rate", o.max_torque_rate_nm_per_s > 0.0 && std::isfinite(o.max_torque_rate_nm_per_s)},
      {"--max-torque-stiffness",
       o.max_torque_stiffness_nm_per_rad >= 0.0 && std::isfinite(o.max_torque_stiffness_nm_per_rad)},
  };
  for (const auto& range : ranges) {
    if (!range.ok) {
      std::fprintf(stderr, "snapthread-device: %s: out of range (see --help)\n", range.flag);
      return kExitBadArguments;
    }
  }
  return kContinue;
}

// The session key: without it nothing the server sends can be trusted.
int LoadSessionKey(const DeviceClientOptions& o, ClientSetup* setup) {
  try {
    const auth::KeyLocation where = auth::ResolveKeyPath(o.key_path);
    setup->key.emplace(auth::LoadKey(where));
    spdlog::info("device: session key {} ({}), key id {}", where.path, where.origin, setup->key->Id());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "snapthread-device: --key: %s\n", e.what());
    return kExitBadArguments;
  }
  return kContinue;
}

// --scene and --grasp: the scene (if any) and the index of the grasp this device holds.
int LoadSceneAndGrasp(const DeviceClientOptions& o, ClientSetup* setup) {
  if (!o.scene_file.empty()) {
    try {
      setup->scene = LoadScene(o.scene_file);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "snapthread-device: --scene: %s\n", e.what());
      return kExitBadArguments;
    }
  }
  if (o.grasp.empty()) return kContinue;
  const std::optional<Scene>& scene = setup->scene;
  setup->grasp = scene ? FindGrasp(*scene, o.grasp) : -1;
  if (setup->grasp >= 0) return kContinue;
  if (!scene) {
    PrintError("--grasp: needs --scene (the scene names the grasps)");
    return kExitBadArguments;
  }
  std::string names;
  for (const SceneGrasp& g : scene->grasps) names += (names.empty() ? "" : ", ") + g.name;
  PrintError("--grasp: no grasp '" + o.grasp + "' in the scene (its grasps: " +
             (names.empty() ? "one, unnamed" : names) + ")");
  return kExitBadArguments;
}

// The scripted path (--path-csv, or the scene's grasp path for a simulated backend) and
// the backend (--backend), built but not open.
int MakeConfiguredBackend(const DeviceClientOptions& o, ClientSetup* setup) {
  BackendConfig& config = setup->config;
  config.name = o.backend;
  try {
    if (!o.path_csv.empty()) {
      config.path = ScriptedPath::FromCsv(o.path_csv, o.speed_m_per_s);
    } else if (setup->scene && BackendNeedsPath(o.backend)) {
      config.path = ScriptedPath::FromScene(*setup->scene, o.speed_m_per_s, setup->grasp,
                                            o.angular_speed_deg_per_s * 3.141592653589793 / 180.0);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "snapthread-device: %s: %s\n",
                 o.path_csv.empty() ? "--scene" : "--path-csv", e.what());
    return kExitBadArguments;
  }
  std::string error;
  setup->backend = MakeBackend(config, &error);
  if (!setup->backend.device) {
    std::fprintf(stderr, "snapthread-device: --backend %s: %s\n", o.backend.c_str(), error.c_str());
    return kExitBadArguments;
  }
  return kContinue;
}

// Opens the device and, with --sim-render-file, starts a simulated backend's render
// thread (a real device renders in hardware: refused).
int OpenDevice(const DeviceClientOptions& o, const Backend& backend) {
  std::string error;
  if (!backend.device->Open(&error)) {
    std::fprintf(stderr, "snapthread-device: backend %s failed to open: %s\n", o.backend.c_str(),
                 error.c_str());
    return kExitRuntimeFailure;
  }
  if (o.sim_render_file.empty()) return kContinue;
  bool started = false;
  if (backend.renderer != nullptr) {
    started = backend.renderer->Start(o.sim_render_file, &error);
  } else {
    error = "only the simulated backends (sim-path, virtual-hand) have a render thread";
  }
  if (!started) {
    std::fprintf(stderr, "snapthread-device: --sim-render-file: %s\n", error.c_str());
    backend.device->Close();
    return kExitBadArguments;
  }
  return kContinue;
}

// The safety limits: the device's, tightened by the scene's grasp mapping, with the
// options' torque, watchdog and rate settings. False with *error when they are invalid.
bool MakeLimits(const DeviceClientOptions& o, const ClientSetup& setup, const DeviceCapabilities& caps,
                SafetyLimits* limits, std::string* error) {
  const DeviceMapping mapping = setup.scene ? GraspDeviceMapping(*setup.scene, setup.grasp) : DeviceMapping{};
  limits->max_torque_nm = o.max_torque_nm;  // LimitsFrom keeps it under the device's own
  *limits = LimitsFrom(caps, setup.scene ? &mapping : nullptr, *limits);
  limits->max_torque_rate_nm_per_s = o.max_torque_rate_nm_per_s;
  limits->max_torque_stiffness_nm_per_rad = o.max_torque_stiffness_nm_per_rad;
  limits->model_timeout_s = 1e-3 * o.model_timeout_ms;
  limits->fade_time_s = 1e-3 * o.fade_ms;
  limits->tick_period_s = 1.0 / o.rate_hz;
  return limits->IsValid(error);
}

// The client's configuration from the options, the device and the scene (limits already
// in cc->limits).
void FillClientConfig(const DeviceClientOptions& o, const ClientSetup& setup, const DeviceCapabilities& caps,
                      DeviceClientConfig* cc) {
  cc->device_id = o.backend == caps.model_name ? o.backend : o.backend + ":" + caps.model_name;
  // Each hand is its own sender (the server keeps one sequence filter per device id).
  if (setup.scene && !setup.scene->grasps.empty()) cc->grasp = setup.scene->grasps[setup.grasp].name;
  if (!cc->grasp.empty()) cc->device_id += "@" + cc->grasp;
  cc->device_has_orientation = caps.has_orientation;
  cc->device_torque_output = caps.has_torque_output;
  cc->tick.publish_divisor = o.publish_divisor;
  cc->tick.trace_divisor = o.trace_divisor;
  cc->loop.rate_hz = o.rate_hz;
  cc->loop.realtime = o.realtime;
  cc->trace_file = o.trace_file;
  cc->key = &*setup.key;
  cc->session = o.session;
  cc->snap_ahead = o.snap_ahead;
}

void LogStart(const DeviceClientOptions& o, const std::string& url, const DeviceClientConfig& cc,
              const DeviceCapabilities& caps) {
  const SafetyLimits& limits = cc.limits;
  spdlog::info("device: {} session {} on {}; limits |F| <= {} N, stiffness <= {} N/m, "
               "slew {} N/s, timeout {} ms, fade {} ms, workspace {} m; orientation {}, torque {}",
               cc.device_id, o.session, url, limits.max_force_n, limits.max_stiffness_n_per_m,
               limits.max_force_rate_n_per_s, 1e3 * limits.model_timeout_s,
               1e3 * limits.fade_time_s, limits.workspace_radius_m,
               caps.has_orientation ? "sensed" : "not sensed",
               caps.has_torque_output
                   ? fmt::format("|τ| <= {} N m, slew {} N m/s, stiffness <= {} N m/rad", limits.max_torque_nm,
                                 limits.max_torque_rate_nm_per_s, limits.max_torque_stiffness_nm_per_rad)
                   : std::string("not rendered"));
}

// The open device's client configuration (limits checked, the path's reach warned
// about, the start logged); the device closed and kExitBadArguments on invalid limits.
int ConfigureClient(const DeviceClientOptions& o, const ClientSetup& setup, const std::string& url,
                    DeviceClientConfig* cc) {
  HapticDevice& device = *setup.backend.device;
  const DeviceCapabilities caps = device.capabilities();
  std::string error;
  if (!MakeLimits(o, setup, caps, &cc->limits, &error)) {
    PrintError(error);
    device.Close();
    return kExitBadArguments;
  }
  const SafetyLimits& limits = cc->limits;
  const std::optional<ScriptedPath>& path = setup.config.path;
  if (path && path->max_radius_m() > limits.workspace_radius_m) {
    spdlog::warn("device: the scripted path reaches {:.3f} m from the origin, beyond the "
                 "workspace radius {:.3f} m: those poses get zero force and are not published",
                 path->max_radius_m(), limits.workspace_radius_m);
  }
  FillClientConfig(o, setup, caps, cc);
  LogStart(o, url, *cc, caps);
  return kContinue;
}

// Runs the client until the duration elapses or SIGINT / SIGTERM arrives, then fades the
// force to zero within the safety ramp (fade_time_s) before the servo loop stops.
void RunUntilStopped(const DeviceClientOptions& o, double fade_time_s, DeviceClient* client) {
  g_stop_requested.store(false);
  InstallSignalHandlers();
  std::string notes;
  client->Start(&notes);
  if (!notes.empty()) spdlog::warn("{}", notes);
  if (o.realtime && client->realtime_active()) spdlog::info("servo: SCHED_FIFO active");
  const int64_t start_us = client->start_us();
  while (!g_stop_requested.load()) {
    if (o.duration_s > 0.0 && Seconds(realtime::MonotonicMicros() - start_us) >= o.duration_s) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (!client->FadeOut(fade_time_s + 0.3)) {
    spdlog::warn("device: the force did not fade to zero within {} ms; stopping anyway",
                 1e3 * fade_time_s + 300.0);
  }
  client->Stop();
}

// The run's summary: logged, and written to --summary (kExitRuntimeFailure when it
// cannot be).
int ReportSummary(const DeviceClientOptions& o, DeviceClient& client, const LcmDeviceTransport& lcm) {
  DeviceClientSummary summary = client.Summary(realtime::MonotonicMicros());
  summary.statuses_superseded = lcm.statuses_superseded();
  summary.statuses_oversized = lcm.statuses_oversized();
  LogSummary(summary);
  if (!o.summary_file.empty() && !WriteSummaryJson(o.summary_file, o, summary)) {
    std::fprintf(stderr, "snapthread-device: --summary: cannot write %s\n", o.summary_file.c_str());
    return kExitRuntimeFailure;
  }
  return kExitOk;
}

// The watchdog, path-speed and torque options of ParseDeviceClientArgs.
void AddSafetyOptions(CLI::App& app, DeviceClientOptions* o) {
  app.add_option("--model-timeout-ms", o->model_timeout_ms, "fade the force when the model is older")
      ->check(CLI::Range(1.0, 10000.0))
      ->capture_default_str();
  app.add_option("--fade-ms", o->fade_ms, "fade-out / fade-in time")
      ->check(CLI::Range(1.0, 10000.0))
      ->capture_default_str();
  app.add_option("--speed-m-per-s", o->speed_m_per_s, "scripted path speed")
      ->check(CLI::Range(1e-6, 10.0))
      ->capture_default_str();
  app.add_option("--angular-speed-deg-per-s", o->angular_speed_deg_per_s,
                 "scripted path turning speed (a rod scene's roll_deg)")
      ->check(CLI::Range(1e-3, 3600.0))
      ->capture_default_str();
  app.add_option("--max-torque-nm", o->max_torque_nm,
                 "torque bound for devices with torque output (never above the device's own)")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  app.add_option("--max-torque-rate", o->max_torque_rate_nm_per_s, "torque slew limit, N m/s")
      ->check(CLI::Range(1e-6, 1e4))
      ->capture_default_str();
  app.add_option("--max-torque-stiffness", o->max_torque_stiffness_nm_per_rad,
                 "bound on the rotational stiffness of a 6-DoF model, N m/rad")
      ->check(CLI::Range(0.0, 1e3))
      ->capture_default_str();
}

}  // namespace

int ParseDeviceClientArgs(int argc, char** argv, DeviceClientOptions* o) {
  CLI::App app{"snapthread-device: 1 kHz haptic device client (servo loop, local force model, "
               "safety) for a snapthread session"};
  app.add_option("--backend", o->backend, "sim-path | virtual-hand | phantom | delta")
      ->check(CLI::IsMember(KnownBackends()))
      ->capture_default_str();
  app.add_option("--scene", o->scene_file, "scene YAML (device mapping, limits, grasp path)")
      ->check(CLI::ExistingFile);
  app.add_option("--grasp", o->grasp, "the scene grasp this device holds (a scene with grasps:; default: the first)");
  app.add_option("--path-csv", o->path_csv, "scripted path CSV x,y[,z] in metres (instead of the scene's)")
      ->check(CLI::ExistingFile);
  app.add_option("--session", o->session, "session name, [A-Za-z0-9_]+")->capture_default_str();
  app.add_option("--lcm-url", o->lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or udpm loopback)");
  app.add_option("--duration", o->duration_s, "seconds to run, 0 = until SIGINT/SIGTERM")
      ->check(CLI::Range(0.0, 1e7))
      ->capture_default_str();
  app.add_option("--rate-hz", o->rate_hz, "servo rate")->check(CLI::Range(100.0, 10000.0))->capture_default_str();
  app.add_option("--publish-divisor", o->publish_divisor, "publish every k-th pose")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  AddSafetyOptions(app, o);
  bool no_rt = false;
  app.add_flag("--no-rt", no_rt, "do not try SCHED_FIFO / mlockall");
  bool no_snap_ahead = false;
  app.add_flag("--no-snap-ahead", no_snap_ahead,
               "render only the server's models: no switch to a post-snap model at a fold "
               "boundary (docs/snap-ahead.md)");
  app.add_option("--log-level", o->log_level, "trace | debug | info | warn | error | off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}))
      ->capture_default_str();
  app.add_option("--trace", o->trace_file, "write a per-tick CSV trace");
  app.add_option("--trace-divisor", o->trace_divisor, "trace every k-th tick")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--summary", o->summary_file, "write a JSON summary at exit");
  app.add_option("--key", o->key_path,
                 "session key file (default: $SNAPTHREAD_KEY_FILE, else "
                 "$XDG_CONFIG_HOME/snapthread/session.key)");
  app.add_option("--sim-render-file", o->sim_render_file,
                 "sim-path / virtual-hand: run the device's own render thread and publish what "
                 "it renders (zero once the servo's command is 5 ms old) in this file");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitBadArguments;
  }
  o->realtime = !no_rt;
  o->snap_ahead = !no_snap_ahead;
  if (!messages::IsValidSessionName(o->session)) {
    std::fprintf(stderr, "snapthread-device: --session '%s': expected [A-Za-z0-9_]+\n",
                 o->session.c_str());
    return kExitBadArguments;
  }
  return -1;
}

int RunDeviceClient(const DeviceClientOptions& o) {
  spdlog::set_level(spdlog::level::from_str(o.log_level));
  // Configuration, in this order; bad input ends the program with kExitBadArguments.
  ClientSetup setup;
  if (const int code = CheckOptions(o); code != kContinue) return code;
  if (const int code = LoadSessionKey(o, &setup); code != kContinue) return code;
  if (const int code = LoadSceneAndGrasp(o, &setup); code != kContinue) return code;
  if (const int code = MakeConfiguredBackend(o, &setup); code != kContinue) return code;

  const std::string url =
      messages::WithReceiveBuffer(messages::ResolveLcmUrl(o.lcm_url), messages::kServiceBufferBytes);
  LcmDeviceTransport lcm(url, o.session);
  if (!lcm.good()) {
    std::fprintf(stderr, "snapthread-device: LCM could not start with URL '%s'.\n  hint: %s\n",
                 url.c_str(), messages::LcmStartHint(url).c_str());
    return kExitRuntimeFailure;
  }
  if (const int code = OpenDevice(o, setup.backend); code != kContinue) return code;
  DeviceClientConfig cc;
  if (const int code = ConfigureClient(o, setup, url, &cc); code != kContinue) return code;

  HapticDevice& device = *setup.backend.device;
  std::unique_ptr<DeviceClient> client;
  try {
    client = std::make_unique<DeviceClient>(&device, &lcm, cc);
  } catch (const std::exception& e) {
    PrintError(e.what());
    device.Close();
    return kExitRuntimeFailure;
  }
  RunUntilStopped(o, cc.limits.fade_time_s, client.get());
  device.Close();
  return ReportSummary(o, *client, lcm);
}

}  // namespace snapthread::device
