#include "device_client_app.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "app/command_line.h"
#include "app/common_flags.h"
#include "app/exit_codes.h"
#include "app/stop_signals.h"
#include "auth/key_file.h"
#include "auth/key_id.h"
#include "auth/key_set.h"
#include "auth/sealed_message.h"
#include "auth/role.h"
#include "device_client.h"
#include "device_keys.h"
#include "device_factory.h"
#include "lcm_transport.h"
#include "messages/lcm_url.h"
#include "realtime/clock.h"
#include "safety.h"
#include "scene/scene.h"
#include "scripted_path.h"

namespace snapthread::device {
namespace {

constexpr const char* kProgram = "snapthread-device";

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
      o.backend.c_str(), o.common.session.c_str(), s.duration_s, u(s.ticks), s.tick_rate_hz,
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

void PrintError(const std::string& what) { std::fprintf(stderr, "%s: %s\n", kProgram, what.c_str()); }

// What RunDeviceClient sets up before the transport: the credential (and the file it
// came from, reloaded on SIGHUP), the scene and its grasp, the backend (built, not open).
struct ClientSetup {
  std::unique_ptr<DeviceKeys> keys;
  std::string key_path;
  std::optional<Scene> scene;
  int grasp = 0;
  BackendConfig config;
  Backend backend;
};

// The ranges CLI11's checks let through ("nan" fails no comparison): app::kExitUsage
// naming the flag, or kContinue.
int CheckOptions(const DeviceClientOptions& o) {
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
      return app::kExitUsage;
    }
  }
  return kContinue;
}

// The name the server knows this device by: the grasp its poses name (--grasp, or the
// scene's grasp), "hand" when they name none (the server's effective grasp name).
std::string DeviceName(const DeviceClientOptions& o, const ClientSetup& setup) {
  if (!o.grasp.empty()) return o.grasp;
  if (setup.scene && !setup.scene->grasps.empty()) return setup.scene->grasps[setup.grasp].name;
  return "";
}

// What --key loaded, as the device: a device credential as it is; on the server host the
// root key acting as device `name` ("hand" when empty). Throws when `name` cannot name a
// device.
auth::KeySet AsDevice(auth::KeySet keys, const std::string& name) {
  if (keys.role() != auth::Role::kServer) return keys;
  return auth::KeySet::ForRole(*keys.root(), auth::Role::kDevice, name.empty() ? "hand" : name);
}

// --key: the device's credential (without it nothing the server sends can be trusted).
// A credential of another device than the grasp held is refused: the server would refuse
// every pose as another grasp's.
int LoadDeviceKeys(const DeviceClientOptions& o, ClientSetup* setup) {
  const std::string name = DeviceName(o, *setup);
  auth::KeyLocation where;
  // Says why it failed (a credential of another role: the role needed).
  std::optional<auth::KeySet> loaded = app::LoadKeySet(o.common, auth::Role::kDevice, kProgram, &where);
  if (!loaded) return app::kExitUsage;
  try {
    auth::KeySet keys = AsDevice(std::move(*loaded), name);
    if (!name.empty() && keys.name() != name) {
      PrintError("--key: " + where.path + " is device '" + keys.name() + "'s credential, but this device holds grasp '" +
                 name + "': the server would refuse every pose. Fix: --key the credential of device '" + name +
                 "' (snapthread-keygen --role device --device " + name + "), or --grasp " + keys.name());
      return app::kExitUsage;
    }
    spdlog::info("device: {} ({}) as device '{}', key id {}", where.path, where.origin, keys.name(),
                 auth::KeyIdToHex(keys.tagger().key_id));
    setup->keys = std::make_unique<DeviceKeys>(std::move(keys), static_cast<int64_t>(1e6 * o.key_grace_s));
    setup->key_path = where.path;
  } catch (const std::exception& e) {
    PrintError(std::string("--key: ") + e.what());
    return app::kExitUsage;
  }
  return kContinue;
}

// SIGHUP: the credential file again. On success the device tags with it from the next
// pose and accepts models under the previous key for --key-grace-s; otherwise it keeps
// the credential it has.
void ReloadDeviceKeys(const ClientSetup& setup) {
  try {
    auth::KeySet next =
        AsDevice(auth::LoadKeySet(setup.key_path, auth::Role::kDevice, kProgram), setup.keys->name());
    const std::string id = auth::KeyIdToHex(next.tagger().key_id);
    const auth::SessionKey previous_read =
        auth::SessionKey::FromBytes(setup.keys->current().read_key().data(), auth::SessionKey::kBytes);
    const auth::SessionKey next_read = auth::SessionKey::FromBytes(next.read_key().data(), auth::SessionKey::kBytes);
    std::string error;
    if (!setup.keys->Replace(std::move(next), realtime::MonotonicMicros(), &error)) {
      spdlog::error("device: reload of {} refused, keeping the current credential: {}", setup.key_path, error);
      return;
    }
    // Sealed messages: open under both read keys (the server seals with the previous one
    // during its grace), seal with the new one.
    auth::SetSealing(next_read, &previous_read, auth::SealingOutgoing());
    spdlog::info("device: reloaded {}: key id {}; the previous key is accepted for {:.0f} s", setup.key_path, id,
                 1e-6 * static_cast<double>(setup.keys->grace_us()));
  } catch (const std::exception& e) {
    spdlog::error("device: reload of {} failed, keeping the current credential: {}", setup.key_path, e.what());
  }
}

// --scene and --grasp: the scene (if any) and the index of the grasp this device holds.
int LoadSceneAndGrasp(const DeviceClientOptions& o, ClientSetup* setup) {
  if (!o.scene_file.empty()) {
    try {
      setup->scene = LoadScene(o.scene_file);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "snapthread-device: --scene: %s\n", e.what());
      return app::kExitUsage;
    }
  }
  if (o.grasp.empty()) return kContinue;
  const std::optional<Scene>& scene = setup->scene;
  setup->grasp = scene ? FindGrasp(*scene, o.grasp) : -1;
  if (setup->grasp >= 0) return kContinue;
  if (!scene) {
    PrintError("--grasp: needs --scene (the scene names the grasps)");
    return app::kExitUsage;
  }
  std::string names;
  for (const SceneGrasp& g : scene->grasps) names += (names.empty() ? "" : ", ") + g.name;
  PrintError("--grasp: no grasp '" + o.grasp + "' in the scene (its grasps: " +
             (names.empty() ? "one, unnamed" : names) + ")");
  return app::kExitUsage;
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
    return app::kExitUsage;
  }
  std::string error;
  setup->backend = MakeBackend(config, &error);
  if (!setup->backend.device) {
    std::fprintf(stderr, "snapthread-device: --backend %s: %s\n", o.backend.c_str(), error.c_str());
    return app::kExitUsage;
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
    return app::kExitFailure;
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
    return app::kExitUsage;
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
  cc->keys = setup.keys.get();
  cc->session = o.common.session;
  cc->snap_ahead = o.snap_ahead;
}

void LogStart(const DeviceClientOptions& o, const std::string& url, const DeviceClientConfig& cc,
              const DeviceCapabilities& caps) {
  const SafetyLimits& limits = cc.limits;
  spdlog::info("device: {} session {} on {}; limits |F| <= {} N, stiffness <= {} N/m, "
               "slew {} N/s, timeout {} ms, fade {} ms, workspace {} m; orientation {}, torque {}",
               cc.device_id, o.common.session, url, limits.max_force_n, limits.max_stiffness_n_per_m,
               limits.max_force_rate_n_per_s, 1e3 * limits.model_timeout_s,
               1e3 * limits.fade_time_s, limits.workspace_radius_m,
               caps.has_orientation ? "sensed" : "not sensed",
               caps.has_torque_output
                   ? fmt::format("|τ| <= {} N m, slew {} N m/s, stiffness <= {} N m/rad", limits.max_torque_nm,
                                 limits.max_torque_rate_nm_per_s, limits.max_torque_stiffness_nm_per_rad)
                   : std::string("not rendered"));
}

// The open device's client configuration (limits checked, the path's reach warned
// about, the start logged); the device closed and app::kExitUsage on invalid limits.
int ConfigureClient(const DeviceClientOptions& o, const ClientSetup& setup, const std::string& url,
                    DeviceClientConfig* cc) {
  HapticDevice& device = *setup.backend.device;
  const DeviceCapabilities caps = device.capabilities();
  std::string error;
  if (!MakeLimits(o, setup, caps, &cc->limits, &error)) {
    PrintError(error);
    device.Close();
    return app::kExitUsage;
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
void RunUntilStopped(const DeviceClientOptions& o, const ClientSetup& setup, double fade_time_s,
                     app::StopSignals* stop, ReloadSignal* reload, DeviceClient* client) {
  std::string notes;
  client->Start(&notes);
  if (!notes.empty()) spdlog::warn("{}", notes);
  if (o.realtime && client->realtime_active()) spdlog::info("servo: SCHED_FIFO active");
  // The main thread waits, and reloads the credential on SIGHUP; the servo thread runs
  // on (the signals are blocked in it).
  constexpr double kReloadPollS = 0.2;
  while (true) {
    double wait_s = kReloadPollS;
    if (o.duration_s > 0.0) {
      const double left = o.duration_s - Seconds(realtime::MonotonicMicros() - client->start_us());
      if (left <= 0.0) break;
      wait_s = std::min(wait_s, left);
    }
    if (stop->Wait(wait_s) != 0) break;
    if (reload != nullptr && reload->Take()) ReloadDeviceKeys(setup);
  }
  if (!client->FadeOut(fade_time_s + 0.3)) {
    spdlog::warn("device: the force did not fade to zero within {} ms; stopping anyway",
                 1e3 * fade_time_s + 300.0);
  }
  client->Stop();
}

// The run's summary: logged, and written to --summary (app::kExitFailure when it
// cannot be).
int ReportSummary(const DeviceClientOptions& o, DeviceClient& client, const LcmDeviceTransport& lcm) {
  DeviceClientSummary summary = client.Summary(realtime::MonotonicMicros());
  summary.statuses_superseded = lcm.statuses_superseded();
  summary.statuses_oversized = lcm.statuses_oversized();
  LogSummary(summary);
  if (!o.summary_file.empty() && !WriteSummaryJson(o.summary_file, o, summary)) {
    std::fprintf(stderr, "snapthread-device: --summary: cannot write %s\n", o.summary_file.c_str());
    return app::kExitFailure;
  }
  return app::kExitOk;
}

// The watchdog, path-speed and torque options of ParseDeviceClientArgs.
void AddSafetyOptions(CLI::App& cli, DeviceClientOptions* o) {
  cli.add_option("--model-timeout-ms", o->model_timeout_ms, "fade the force when the model is older")
      ->check(CLI::Range(1.0, 10000.0))
      ->capture_default_str();
  cli.add_option("--fade-ms", o->fade_ms, "fade-out / fade-in time")
      ->check(CLI::Range(1.0, 10000.0))
      ->capture_default_str();
  cli.add_option("--speed-m-per-s", o->speed_m_per_s, "scripted path speed")
      ->check(CLI::Range(1e-6, 10.0))
      ->capture_default_str();
  cli.add_option("--angular-speed-deg-per-s", o->angular_speed_deg_per_s,
                 "scripted path turning speed (a rod scene's roll_deg)")
      ->check(CLI::Range(1e-3, 3600.0))
      ->capture_default_str();
  cli.add_option("--max-torque-nm", o->max_torque_nm,
                 "torque bound for devices with torque output (never above the device's own)")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  cli.add_option("--max-torque-rate", o->max_torque_rate_nm_per_s, "torque slew limit, N m/s")
      ->check(CLI::Range(1e-6, 1e4))
      ->capture_default_str();
  cli.add_option("--max-torque-stiffness", o->max_torque_stiffness_nm_per_rad,
                 "bound on the rotational stiffness of a 6-DoF model, N m/rad")
      ->check(CLI::Range(0.0, 1e3))
      ->capture_default_str();
}

}  // namespace

std::optional<int> ParseDeviceClientArgs(int argc, char** argv, DeviceClientOptions* o) {
  CLI::App cli{"snapthread-device: 1 kHz haptic device client (servo loop, local force model, "
               "safety) for a snapthread session"};
  cli.add_option("--backend", o->backend, "sim-path | virtual-hand | phantom | delta")
      ->check(CLI::IsMember(KnownBackends()))
      ->capture_default_str();
  cli.add_option("--scene", o->scene_file, "scene YAML (device mapping, limits, grasp path)")
      ->check(CLI::ExistingFile);
  cli.add_option("--grasp", o->grasp, "the scene grasp this device holds (a scene with grasps:; default: the first)");
  cli.add_option("--path-csv", o->path_csv, "scripted path CSV x,y[,z] in metres (instead of the scene's)")
      ->check(CLI::ExistingFile);
  app::CommonFlagSet common;
  common.log_level = true;
  common.encrypt = true;
  app::AddCommonFlags(&cli, &o->common, common);
  cli.add_option("--duration", o->duration_s, "seconds to run, 0 = until SIGINT/SIGTERM")
      ->check(CLI::Range(0.0, 1e7))
      ->capture_default_str();
  cli.add_option("--rate-hz", o->rate_hz, "servo rate")->check(CLI::Range(100.0, 10000.0))->capture_default_str();
  cli.add_option("--publish-divisor", o->publish_divisor, "publish every k-th pose")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  AddSafetyOptions(cli, o);
  bool no_rt = false;
  cli.add_flag("--no-rt", no_rt, "do not try SCHED_FIFO / mlockall");
  bool no_snap_ahead = false;
  cli.add_flag("--no-snap-ahead", no_snap_ahead,
               "render only the server's models: no switch to a post-snap model at a fold "
               "boundary (docs/snap-ahead.md)");
  cli.add_option("--key-grace-s", o->key_grace_s,
                 "after a reload (SIGHUP) of --key, accept force models under the previous key this long")
      ->check(CLI::Range(0.0, 86400.0))
      ->capture_default_str();
  cli.add_option("--trace", o->trace_file, "write a per-tick CSV trace");
  cli.add_option("--trace-divisor", o->trace_divisor, "trace every k-th tick")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cli.add_option("--summary", o->summary_file, "write a JSON summary at exit");
  cli.add_option("--sim-render-file", o->sim_render_file,
                 "sim-path / virtual-hand: run the device's own render thread and publish what "
                 "it renders (zero once the servo's command is 5 ms old) in this file");
  if (auto code = app::ParseCommandLine(cli, argc, argv, app::kExitUsage)) return code;
  o->realtime = !no_rt;
  o->snap_ahead = !no_snap_ahead;
  return app::CheckCommonFlags(o->common, kProgram, app::kExitUsage);
}

int RunDeviceClient(const DeviceClientOptions& o, app::StopSignals* stop, ReloadSignal* reload) {
  spdlog::set_level(spdlog::level::from_str(o.common.log_level));
  // Configuration, in this order; bad input ends the program with app::kExitUsage.
  ClientSetup setup;
  if (const int code = CheckOptions(o); code != kContinue) return code;
  if (const int code = LoadSceneAndGrasp(o, &setup); code != kContinue) return code;
  if (const int code = LoadDeviceKeys(o, &setup); code != kContinue) return code;
  if (const int code = MakeConfiguredBackend(o, &setup); code != kContinue) return code;

  const std::string url = app::LcmUrl(o.common, messages::kServiceBufferBytes);
  LcmDeviceTransport lcm(url, o.common.session);
  if (!lcm.good()) {
    std::fprintf(stderr, "snapthread-device: LCM could not start with URL '%s'.\n  hint: %s\n",
                 url.c_str(), messages::LcmStartHint(url).c_str());
    return app::kExitFailure;
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
    return app::kExitFailure;
  }
  RunUntilStopped(o, setup, cc.limits.fade_time_s, stop, reload, client.get());
  device.Close();
  return ReportSummary(o, *client, lcm);
}

}  // namespace snapthread::device
