#include "device_client_app.h"

#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>

#include "device_factory.h"
#include "safety.h"
#include "scripted_path.h"
#include "servo_loop.h"
#include "snapthread/device_state_t.hpp"
#include "snapthread/device_status_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "scene/scene.h"
#include "messages/channels.h"
#include "realtime/clock.h"
#include "messages/lcm_url.h"
#include "realtime/percentiles.h"
#include "messages/validate.h"

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

// Receives force models on the LCM thread and hands them to the servo thread.
class ModelReceiver {
 public:
  ModelReceiver(const SafetyLimits& limits, ModelSlot* slot) : limits_(limits), slot_(slot) {}

  void Handle(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
    // LCM handlers must never throw.
    try {
      const int64_t now_us = transport::MonotonicMicros();
      force_model_t msg;
      std::string why;
      if (!transport::DecodeAndValidate(rbuf, &msg, &why)) {
        Reject(why);
        return;
      }
      LocalModel model;
      const ModelVerdict verdict = PrepareModel(msg, now_us, limits_, &model, &why);
      if (verdict == ModelVerdict::kRejected) {
        Reject(why);
        return;
      }
      if (verdict == ModelVerdict::kStiffnessClamped) stiffness_clamps_.fetch_add(1);
      if (verdict == ModelVerdict::kInvalidStatus) invalid_models_.fetch_add(1);
      if (msg.status == force_model_t::STATUS_SNAPPED) snaps_felt_.fetch_add(1);
      slot_->Write(model);
      received_.fetch_add(1);
      // Round trip on the device's own clock: pose time echoed back by the server.
      const int64_t rt = now_us - msg.device_utime;
      if (msg.device_utime > 0 && rt >= 0 && rt < 10000000) {
        std::lock_guard<std::mutex> lock(mutex_);
        round_trip_window_.Push(static_cast<double>(rt));
        round_trip_run_.Push(static_cast<double>(rt));
      }
    } catch (...) {
      rejected_.fetch_add(1);
    }
  }

  transport::PercentileSummary RoundTrip(bool whole_run) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return whole_run ? round_trip_run_.Compute() : round_trip_window_.Compute();
  }

  uint64_t received() const { return received_.load(); }
  uint64_t rejected() const { return rejected_.load(); }
  uint64_t stiffness_clamps() const { return stiffness_clamps_.load(); }
  uint64_t invalid_models() const { return invalid_models_.load(); }
  uint64_t snaps_felt() const { return snaps_felt_.load(); }

 private:
  void Reject(const std::string& why) {
    const uint64_t n = rejected_.fetch_add(1) + 1;
    // Rate-limited: a flood of garbage must not become a flood of log lines.
    if (n <= 5 || n % 1000 == 0) {
      spdlog::warn("device: force model rejected ({} so far): {}", n, why);
    }
  }

  SafetyLimits limits_;
  ModelSlot* slot_;
  std::atomic<uint64_t> received_{0}, rejected_{0}, stiffness_clamps_{0}, invalid_models_{0},
      snaps_felt_{0};
  mutable std::mutex mutex_;
  transport::SampleWindow round_trip_window_{2000};
  transport::SampleWindow round_trip_run_{200000};
};

struct RunStats {
  transport::SampleWindow lateness_window{1000};     // last second, for DEVICE_STATUS
  transport::SampleWindow lateness_run{600000};      // last 10 min at 1 kHz, for the summary
  double lateness_max_us = 0.0;
};

void WriteTraceHeader(FILE* f) {
  std::fputs("t_s,seq,x_m,y_m,z_m,fx_n,fy_n,fz_n,model_age_ms,model_status,clamped,fading\n", f);
}

void WriteTraceRow(FILE* f, const TraceRow& r, int64_t start_us) {
  std::fprintf(f, "%.6f,%lld,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.3f,%d,%d,%d\n",
               Seconds(r.utime_us - start_us), static_cast<long long>(r.tick), r.position_m[0],
               r.position_m[1], r.position_m[2], r.force_n[0], r.force_n[1], r.force_n[2],
               r.model_age_ms, static_cast<int>(r.model_status), r.clamped ? 1 : 0,
               r.fading ? 1 : 0);
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
  app.add_option("--model-timeout-ms", o->model_timeout_ms, "fade the force when the model is older")
      ->check(CLI::Range(1.0, 10000.0))
      ->capture_default_str();
  app.add_option("--fade-ms", o->fade_ms, "fade-out / fade-in time")
      ->check(CLI::Range(1.0, 10000.0))
      ->capture_default_str();
  app.add_option("--speed-m-per-s", o->speed_m_per_s, "scripted path speed")
      ->check(CLI::Range(1e-6, 10.0))
      ->capture_default_str();
  bool no_rt = false;
  app.add_flag("--no-rt", no_rt, "do not try SCHED_FIFO / mlockall");
  app.add_option("--log-level", o->log_level, "trace | debug | info | warn | error | off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}))
      ->capture_default_str();
  app.add_option("--trace", o->trace_file, "write a per-tick CSV trace");
  app.add_option("--trace-divisor", o->trace_divisor, "trace every k-th tick")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--summary", o->summary_file, "write a JSON summary at exit");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitBadArguments;
  }
  o->realtime = !no_rt;
  if (!transport::IsValidSessionName(o->session)) {
    std::fprintf(stderr, "snapthread-device: --session '%s': expected [A-Za-z0-9_]+\n",
                 o->session.c_str());
    return kExitBadArguments;
  }
  return -1;
}

int RunDeviceClient(const DeviceClientOptions& o) {
  spdlog::set_level(spdlog::level::from_str(o.log_level));
  if (!transport::IsValidSessionName(o.session)) {
    std::fprintf(stderr, "snapthread-device: --session '%s': expected [A-Za-z0-9_]+\n",
                 o.session.c_str());
    return kExitBadArguments;
  }
  if (!(o.rate_hz >= 100.0 && o.rate_hz <= 10000.0) || o.publish_divisor < 1 ||
      o.trace_divisor < 1 || !(o.model_timeout_ms > 0.0) || !(o.fade_ms > 0.0) ||
      !(o.speed_m_per_s > 0.0) || !(o.duration_s >= 0.0)) {
    std::fprintf(stderr, "snapthread-device: options out of range (see --help)\n");
    return kExitBadArguments;
  }
  const transport::Channels channels(o.session);

  // ---- configuration: scene, path, backend, limits (bad input -> exit 2) --------------
  std::optional<Scene> scene;
  if (!o.scene_file.empty()) {
    try {
      scene = LoadScene(o.scene_file);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "snapthread-device: --scene: %s\n", e.what());
      return kExitBadArguments;
    }
  }
  BackendConfig config;
  config.name = o.backend;
  try {
    if (!o.path_csv.empty()) {
      config.path = ScriptedPath::FromCsv(o.path_csv, o.speed_m_per_s);
    } else if (scene && BackendNeedsPath(o.backend)) {
      config.path = ScriptedPath::FromScene(*scene, o.speed_m_per_s);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "snapthread-device: %s: %s\n",
                 o.path_csv.empty() ? "--scene" : "--path-csv", e.what());
    return kExitBadArguments;
  }
  std::string error;
  std::unique_ptr<HapticDevice> device = MakeDevice(config, &error);
  if (!device) {
    std::fprintf(stderr, "snapthread-device: --backend %s: %s\n", o.backend.c_str(), error.c_str());
    return kExitBadArguments;
  }

  // ---- LCM ----------------------------------------------------------------------------
  const std::string url = transport::ResolveLcmUrl(o.lcm_url);
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "snapthread-device: LCM could not start with URL '%s'.\n  hint: %s\n",
                 url.c_str(), transport::LcmStartHint(url).c_str());
    return kExitRuntimeFailure;
  }

  if (!device->Open(&error)) {
    std::fprintf(stderr, "snapthread-device: backend %s failed to open: %s\n", o.backend.c_str(),
                 error.c_str());
    return kExitRuntimeFailure;
  }
  const DeviceCapabilities caps = device->capabilities();
  SafetyLimits limits = LimitsFrom(caps, scene ? &scene->device : nullptr);
  limits.model_timeout_s = 1e-3 * o.model_timeout_ms;
  limits.fade_time_s = 1e-3 * o.fade_ms;
  limits.tick_period_s = 1.0 / o.rate_hz;
  if (!limits.IsValid(&error)) {
    std::fprintf(stderr, "snapthread-device: %s\n", error.c_str());
    device->Close();
    return kExitBadArguments;
  }
  if (config.path && config.path->max_radius_m() > limits.workspace_radius_m) {
    spdlog::warn("device: the scripted path reaches {:.3f} m from the origin, beyond the "
                 "workspace radius {:.3f} m: those poses get zero force and are not published",
                 config.path->max_radius_m(), limits.workspace_radius_m);
  }
  const std::string device_id = o.backend == caps.model_name ? o.backend : o.backend + ":" + caps.model_name;
  spdlog::info("device: {} session {} on {}; limits |F| <= {} N, stiffness <= {} N/m, "
               "slew {} N/s, timeout {} ms, fade {} ms, workspace {} m",
               device_id, o.session, url, limits.max_force_n, limits.max_stiffness_n_per_m,
               limits.max_force_rate_n_per_s, 1e3 * limits.model_timeout_s,
               1e3 * limits.fade_time_s, limits.workspace_radius_m);

  // ---- wiring -------------------------------------------------------------------------
  ForceSafety safety(limits, caps.has_orientation);
  auto models = std::make_unique<ModelSlot>();
  auto poses = std::make_unique<PoseRing>();
  auto trace_ring = std::make_unique<TraceRing>();
  auto lateness = std::make_unique<LatenessRing>();
  FILE* trace_file = nullptr;
  if (!o.trace_file.empty()) {
    trace_file = std::fopen(o.trace_file.c_str(), "w");
    if (!trace_file) {
      std::fprintf(stderr, "snapthread-device: --trace: cannot write %s\n", o.trace_file.c_str());
      device->Close();
      return kExitRuntimeFailure;
    }
    WriteTraceHeader(trace_file);
  }
  ServoTickOptions tick_options;
  tick_options.publish_divisor = o.publish_divisor;
  tick_options.trace_divisor = o.trace_divisor;
  ServoTick tick(device.get(), &safety, models.get(), poses.get(),
                 trace_file ? trace_ring.get() : nullptr, lateness.get(), tick_options);

  ModelReceiver receiver(limits, models.get());
  lcm.subscribe(channels.force_model, &ModelReceiver::Handle, &receiver);

  g_stop_requested.store(false);
  InstallSignalHandlers();

  std::atomic<bool> stop_threads{false};
  std::thread lcm_thread([&] {
    while (!stop_threads.load()) {
      // < 0: the provider failed; do not spin (the watchdog fades the force meanwhile).
      if (lcm.handleTimeout(20) < 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });

  ServoLoopOptions loop_options;
  loop_options.rate_hz = o.rate_hz;
  loop_options.realtime = o.realtime;
  ServoLoop loop(&tick, loop_options);
  const int64_t start_us = transport::MonotonicMicros();
  std::string notes;
  loop.Start(&notes);
  if (!notes.empty()) spdlog::warn("{}", notes);
  if (o.realtime && loop.realtime_active()) spdlog::info("servo: SCHED_FIFO active");

  RunStats stats;
  std::atomic<uint64_t> status_seq{0};
  auto publish_status = [&](int64_t now_us, double tick_rate_hz) {
    device_status_t st{};
    st.utime = now_us;
    st.seq = static_cast<int64_t>(status_seq.fetch_add(1));
    st.device_id = device_id;
    st.tick_rate_hz = tick_rate_hz;
    const auto lat = stats.lateness_window.Compute();
    st.lateness_us_p50 = lat.p50;
    st.lateness_us_p99 = lat.p99;
    st.lateness_us_max = lat.max;
    const int64_t rx = tick.counters().last_model_receive_us.load();
    st.model_age_ms = rx >= 0 ? 1e-3 * static_cast<double>(now_us - rx) : -1.0;
    const auto rt = receiver.RoundTrip(false);
    st.round_trip_us_p50 = rt.p50;
    st.round_trip_us_p99 = rt.p99;
    st.force_norm_n = tick.counters().force_norm_n.load();
    st.ticks = static_cast<int64_t>(tick.counters().ticks.load());
    st.models_received = static_cast<int64_t>(receiver.received());
    st.models_rejected = static_cast<int64_t>(receiver.rejected());
    st.force_clamps = static_cast<int64_t>(safety.counters().force_clamps.load());
    st.stiffness_clamps = static_cast<int64_t>(receiver.stiffness_clamps());
    st.slew_limits = static_cast<int64_t>(safety.counters().slew_limits.load());
    st.fades = static_cast<int64_t>(safety.counters().fade_ticks.load());
    st.snaps_felt = static_cast<int64_t>(receiver.snaps_felt());
    std::string why;
    if (transport::Validate(st, &why)) lcm.publish(channels.device_status, &st);
  };

  std::atomic<uint64_t> invalid_poses_unpublished{0};
  std::thread io_thread([&] {
    device_state_t msg{};
    msg.device_id = device_id;
    int64_t last_status_us = start_us;
    int64_t last_log_us = start_us;
    uint64_t last_status_ticks = 0;
    auto drain = [&] {
      PoseSample p;
      while (poses->TryPop(&p)) {
        msg.utime = p.utime_us;
        msg.seq = p.seq;
        for (int k = 0; k < 3; ++k) msg.position[k] = p.position_m[k];
        for (int k = 0; k < 4; ++k) msg.orientation[k] = p.orientation[k];
        msg.buttons = p.buttons;
        // The servo already refused bad positions; this also catches a backend's bad
        // orientation, so the server never receives a pose it would have to reject.
        if (transport::Validate(msg, nullptr)) {
          lcm.publish(channels.device_state, &msg);
        } else {
          invalid_poses_unpublished.fetch_add(1);
        }
      }
      TraceRow r;
      while (trace_ring->TryPop(&r)) {
        if (trace_file) WriteTraceRow(trace_file, r, start_us);
      }
      int32_t l;
      while (lateness->TryPop(&l)) {
        stats.lateness_window.Push(l);
        stats.lateness_run.Push(l);
        if (l > stats.lateness_max_us) stats.lateness_max_us = l;
      }
    };
    while (!stop_threads.load()) {
      drain();
      const int64_t now = transport::MonotonicMicros();
      if (now - last_status_us >= 500000) {
        const uint64_t ticks = tick.counters().ticks.load();
        const double rate = static_cast<double>(ticks - last_status_ticks) / Seconds(now - last_status_us);
        publish_status(now, rate);
        last_status_ticks = ticks;
        last_status_us = now;
        if (now - last_log_us >= 5000000) {
          const auto lat = stats.lateness_window.Compute();
          const auto rt = receiver.RoundTrip(false);
          spdlog::info("device: {:.0f} Hz, lateness p50/p99/max {:.0f}/{:.0f}/{:.0f} us, "
                       "round trip p50/p99 {:.0f}/{:.0f} us, models {} (+{} rejected), |F| {:.3f} N, "
                       "clamps {}, slew {}, fade ticks {}, snaps {}",
                       rate, lat.p50, lat.p99, lat.max, rt.p50, rt.p99, receiver.received(),
                       receiver.rejected(), tick.counters().force_norm_n.load(),
                       safety.counters().force_clamps.load(), safety.counters().slew_limits.load(),
                       safety.counters().fade_ticks.load(), receiver.snaps_felt());
          last_log_us = now;
        }
      }
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
    drain();
  });

  // ---- run until the duration elapses or a signal arrives ---------------------------------
  while (!g_stop_requested.load()) {
    if (o.duration_s > 0.0 && Seconds(transport::MonotonicMicros() - start_us) >= o.duration_s) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  loop.Stop();
  const int64_t end_us = transport::MonotonicMicros();
  const double zero[3] = {0.0, 0.0, 0.0};
  device->Command(zero, zero);
  device->Close();
  stop_threads.store(true);
  io_thread.join();
  lcm_thread.join();
  if (trace_file) std::fclose(trace_file);

  // ---- summary ---------------------------------------------------------------------------
  const uint64_t ticks = tick.counters().ticks.load();
  const double run_s = Seconds(end_us - start_us);
  const double tick_rate = run_s > 0.0 ? static_cast<double>(ticks) / run_s : 0.0;
  const auto lat = stats.lateness_run.Compute();
  const auto rt = receiver.RoundTrip(true);
  const SafetyCounters& sc = safety.counters();
  spdlog::info("device: done after {:.2f} s: {} ticks ({:.1f} Hz), lateness p50/p99/max "
               "{:.0f}/{:.0f}/{:.0f} us, round trip p50/p99 {:.0f}/{:.0f} us, models {} "
               "received / {} rejected, poses rejected {}, force clamps {}, stiffness clamps {}, "
               "slew limits {}, fade ticks {}, snaps felt {}, max |F| {:.3f} N, non-finite "
               "outputs {}, overruns {}",
               run_s, ticks, tick_rate, lat.p50, lat.p99, stats.lateness_max_us, rt.p50, rt.p99,
               receiver.received(), receiver.rejected(), sc.poses_rejected.load(),
               sc.force_clamps.load(), receiver.stiffness_clamps(), sc.slew_limits.load(),
               sc.fade_ticks.load(), receiver.snaps_felt(), safety.max_force_n(),
               sc.nonfinite_outputs.load(), loop.overruns());
  if (!o.summary_file.empty()) {
    FILE* f = std::fopen(o.summary_file.c_str(), "w");
    if (!f) {
      std::fprintf(stderr, "snapthread-device: --summary: cannot write %s\n", o.summary_file.c_str());
      return kExitRuntimeFailure;
    }
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
        "  \"max_force_n\": %.6f,\n  \"nonfinite_outputs\": %llu,\n  \"overruns\": %llu,\n"
        "  \"read_failures\": %llu,\n  \"pose_ring_drops\": %llu,\n  \"trace_ring_drops\": %llu,\n"
        "  \"invalid_poses_unpublished\": %llu,\n  \"realtime\": %s\n}\n",
        o.backend.c_str(), o.session.c_str(), run_s, u(ticks), tick_rate, lat.p50, lat.p99,
        stats.lateness_max_us, rt.p50, rt.p99, u(receiver.received()), u(receiver.rejected()),
        u(receiver.invalid_models()), u(sc.poses_rejected.load()), u(sc.force_clamps.load()),
        u(receiver.stiffness_clamps()), u(sc.slew_limits.load()), u(sc.fade_ticks.load()),
        u(receiver.snaps_felt()), safety.max_force_n(), u(sc.nonfinite_outputs.load()),
        u(loop.overruns()), u(tick.counters().read_failures.load()), u(poses->dropped()),
        u(trace_ring->dropped()), u(invalid_poses_unpublished.load()),
        loop.realtime_active() ? "true" : "false");
    std::fclose(f);
  }
  return kExitOk;
}

}  // namespace snapthread::device
