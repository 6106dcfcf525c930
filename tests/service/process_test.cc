// snapthread-server and snapthread-device as real, separate processes over UDP multicast
// on loopback (ttl=0), one unique session per test. The machine is shared (2 cores, other
// builds and tests running): timeouts are generous and assertions are on distributions
// over thousands of servo ticks, never on single timings.
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "messages/pose_mapping.h"
#include "models/models.h"
#include "scene/scene.h"
#include "tracking/tracker.h"
#include "test_support.h"

namespace snapthread::server {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr const char* kUrl = test_support::kLoopbackLcmUrl;
using test_support::ChildProcess;

// stdout and stderr in one log, no stdin.
test_support::ChildOptions LogTo(const std::string& path) { return test_support::OneLog(path, /*close_stdin=*/true); }

struct TraceRow {
  double t_s, x, y, z, fx, fy, fz, model_age_ms;
  int64_t seq;
  int status, clamped, fading;
  double force_norm() const { return std::sqrt(fx * fx + fy * fy + fz * fz); }
};

std::vector<TraceRow> ReadTrace(const std::string& path) {
  std::vector<TraceRow> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    TraceRow r{};
    long long seq = 0;
    if (std::sscanf(line.c_str(), "%lf,%lld,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%d,%d,%d", &r.t_s, &seq,
                    &r.x, &r.y, &r.z, &r.fx, &r.fy, &r.fz, &r.model_age_ms, &r.status, &r.clamped,
                    &r.fading) == 12) {
      r.seq = seq;
      rows.push_back(r);
    }
  }
  return rows;
}

using test_support::ReadJsonNumbers;

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5));
  return v[k];
}

class ProcessTest : public ::testing::Test {
 protected:
  // The session key every binary of the test uses (SNAPTHREAD_KEY_FILE, inherited).
  const test_support::SessionKeyFile key_file_;

  void SetUp() override {
    bin_ = test_support::BinDir();
    source_ = test_support::SourceDir();
    ASSERT_FALSE(bin_.empty() || source_.empty())
        << "SNAPTHREAD_BIN_DIR / SNAPTHREAD_SOURCE_DIR not set (run through ctest)";
    ASSERT_TRUE(fs::exists(bin_ + "/snapthread-server")) << bin_ << "/snapthread-server not built";
    ASSERT_TRUE(fs::exists(bin_ + "/snapthread-device")) << bin_ << "/snapthread-device not built";
    {
      lcm::LCM probe(kUrl);
      ASSERT_TRUE(probe.good()) << "LCM udpm does not start here: no multicast route? "
                                   "Run deploy/multicast-route.sh (ip route add 224.0.0.0/4 dev lo)";
    }
    // Unique per process, test and run: parallel ctest jobs share the multicast group.
    // (LCM channel names are at most 63 bytes: keep it short.)
    session_ = test_support::UniqueSession("PT");
    tmp_ = std::make_unique<test_support::ScopedTempDir>("process_" + session_);
    dir_ = tmp_->path();
    scene_path_ = source_ + "/scenes/curve2d_snap.yaml";
    scene_ = LoadScene(scene_path_);
  }

  // A path through the strip's snap: from the scene's start (bent up, y = -3) up to
  // y = 3.8 (the bent-up branch ends at y ~ 3.42 and the strip snaps to bent down), and
  // back. Written as device metres for the device's --path-csv.
  std::string WriteSnapPath() {
    const Vec a = scene_.grasp_start;
    const Vec b = (Vec(2) << a[0], 3.8).finished();
    const std::string path = dir_ + "/path.csv";
    std::ofstream out(path);
    for (const Vec& u : {a, b}) {
      const Eigen::Vector3d p = messages::ControlsToPosition(scene_.device, scene_.grasp_layout, u);
      out << p[0] << "," << p[1] << "," << p[2] << "\n";
    }
    return path;
  }

  std::unique_ptr<ChildProcess> StartServer(const std::string& tag) {
    auto child = std::make_unique<ChildProcess>(
        std::vector<std::string>{bin_ + "/snapthread-server", "--scene", scene_path_, "--session",
                                 session_, "--lcm-url", kUrl, "--summary",
                                 dir_ + "/server_" + tag + ".json", "--log-level", "info",
                                 // A safety net should the test die without its cleanup;
                                 // the tests stop it with SIGTERM long before.
                                 "--duration", "300"},
        LogTo(dir_ + "/server_" + tag + ".log"));
    EXPECT_TRUE(child->started());
    // Up when it has logged its session line (scene loaded, LCM started, subscribed).
    EXPECT_TRUE(child->WaitForOutput("server: session", 30)) << child->Out();
    return child;
  }

  std::unique_ptr<ChildProcess> StartDevice(double duration_s, const std::string& path_csv,
                                     double speed) {
    std::ostringstream dur, spd;
    dur << duration_s;
    spd << speed;
    std::vector<std::string> argv{bin_ + "/snapthread-device", "--backend", "sim-path", "--scene",
                                  scene_path_, "--speed-m-per-s", spd.str(),
                                  "--session", session_, "--lcm-url", kUrl, "--duration", dur.str(),
                                  "--rate-hz", "1000", "--publish-divisor", "1",
                                  "--model-timeout-ms", std::to_string(kTimeoutMs), "--fade-ms",
                                  std::to_string(kFadeMs), "--no-rt", "--trace",
                                  dir_ + "/trace.csv", "--summary", dir_ + "/device.json"};
    // Empty: the scene's own grasp path.
    if (!path_csv.empty()) {
      argv.push_back("--path-csv");
      argv.push_back(path_csv);
    }
    auto child = std::make_unique<ChildProcess>(argv, LogTo(dir_ + "/device.log"));
    EXPECT_TRUE(child->started());
    return child;
  }

  // The force the device should feel at each traced position: an EquilibriumTracker run
  // offline along the recorded positions in order, mapped to newtons (x, y).
  std::vector<Eigen::Vector2d> Reference(const std::vector<TraceRow>& rows, int* snaps) {
    EquilibriumTracker tracker(MakeModel(scene_.params), scene_.solver);
    tracker.Reset(scene_.grasp_start);
    std::vector<Eigen::Vector2d> ref;
    *snaps = 0;
    for (const TraceRow& r : rows) {
      const Vec u = messages::PoseToControls(scene_.device, scene_.grasp_layout,
                                             Eigen::Vector3d(r.x, r.y, r.z), Eigen::Vector4d(1, 0, 0, 0));
      const TrackResult& t = tracker.Update(u);
      if (t.snapped) ++*snaps;
      ref.emplace_back(scene_.device.newtons_per_model_force * t.force[0],
                       scene_.device.newtons_per_model_force * t.force[1]);
    }
    return ref;
  }

  static constexpr int kTimeoutMs = 50;
  static constexpr int kFadeMs = 100;
  // Logs and traces: kept for the post-mortem of a failed test, dropped otherwise.
  std::unique_ptr<test_support::ScopedTempDir> tmp_;
  std::string bin_, source_, session_, dir_, scene_path_;
  Scene scene_;
};

TEST_F(ProcessTest, DeviceFeelsTheServersForceThroughTheSnap) {
  const std::string path = WriteSnapPath();
  auto server = StartServer("a");
  // 0.136 m up at 0.03 m/s: the snap (y = 3.42) comes at ~4.3 s, then part of the way back.
  auto device = StartDevice(7.0, path, 0.03);
  int code = -1;
  ASSERT_TRUE(device->Wait(120, &code)) << "device did not finish";
  EXPECT_EQ(code, 0) << device->Out();
  server->Signal(SIGTERM);
  ASSERT_TRUE(server->Wait(60, &code)) << "server did not stop on SIGTERM";
  EXPECT_EQ(code, 0) << server->Out();
  EXPECT_NE(server->Out().find("final: updates="), std::string::npos) << server->Out();

  auto dev = ReadJsonNumbers(dir_ + "/device.json");
  auto srv = ReadJsonNumbers(dir_ + "/server_a.json");
  ASSERT_GT(dev.count("ticks"), 0u) << device->Out();
  ASSERT_GT(srv.count("updates"), 0u) << server->Out();
  // The device got models for the bulk of its ticks (poses are superseded when the
  // server is busy, so not one per tick).
  EXPECT_GT(dev["ticks"], 3000);
  EXPECT_GT(dev["models_received"], 0.5 * dev["ticks"]);
  EXPECT_EQ(dev["models_rejected"], 0);
  EXPECT_EQ(dev["nonfinite_outputs"], 0);
  EXPECT_GT(dev["round_trip_us_p50"], 0.0);
  EXPECT_GE(dev["round_trip_us_p99"], dev["round_trip_us_p50"]);
  EXPECT_GE(dev["snaps_felt"], 1);
  EXPECT_GE(srv["snaps"], 1);
  // The only refusals: poses the device signed with epoch 0 before it heard the server's
  // first authenticated status (docs/security.md) — a start-up moment, not a steady loss.
  EXPECT_LT(srv["rejected_messages"], 0.05 * dev["ticks"]);
  EXPECT_GT(srv["updates"], 0.5 * dev["ticks"]);
  EXPECT_GT(srv["solve_us_p50"], 0.0);
  // Every pose the server saw was answered or superseded.
  EXPECT_EQ(srv["updates"] + srv["dropped_poses"], srv["poses_received"]);

  const auto rows = ReadTrace(dir_ + "/trace.csv");
  ASSERT_GT(rows.size(), 3000u);
  int ref_snaps = 0;
  const auto ref = Reference(rows, &ref_snaps);
  EXPECT_GE(ref_snaps, 1) << "the path must cross the snap";
  // Compare where the device renders the model as is: a fresh model, no fade, no clamp.
  std::vector<double> errors;
  double max_ref = 0.0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const TraceRow& r = rows[i];
    EXPECT_TRUE(std::isfinite(r.fx) && std::isfinite(r.fy) && std::isfinite(r.fz));
    if (r.fading || r.clamped || r.status < 0 || r.model_age_ms > kTimeoutMs || r.t_s < 0.5) continue;
    errors.push_back(std::hypot(r.fx - ref[i][0], r.fy - ref[i][1]));
    max_ref = std::max(max_ref, ref[i].norm());
  }
  ASSERT_GT(errors.size(), rows.size() / 2) << "too few ticks with a fresh model";
  // The device's linearisation (K clamped to the stable range) and a few ms of latency
  // make small differences; the snap itself is a few ticks of large ones.
  const double p50 = Percentile(errors, 0.5), p95 = Percentile(errors, 0.95);
  EXPECT_GT(max_ref, 0.2) << "the reference force should be felt";
  EXPECT_LT(p50, 0.01) << "median |F_device - F_reference| in N";
  EXPECT_LT(p95, 0.05) << "95th percentile |F_device - F_reference| in N";
  std::printf("compared %zu ticks: |dF| p50 %.4f N, p95 %.4f N, max %.3f N; max |F_ref| %.3f N\n",
              errors.size(), p50, p95, Percentile(errors, 1.0), max_ref);
  std::printf("device: round trip p50 %.0f us p99 %.0f us, models %0.f of %0.f ticks; server: "
              "%0.f updates, solve p50 %.1f us p99 %.1f us\n",
              dev["round_trip_us_p50"], dev["round_trip_us_p99"], dev["models_received"],
              dev["ticks"], srv["updates"], srv["solve_us_p50"], srv["solve_us_p99"]);
}

TEST_F(ProcessTest, ServerKilledForceFadesThenRecoversWithANewServer) {
  const std::string path = WriteSnapPath();
  auto server_a = StartServer("a");
  auto device = StartDevice(9.0, path, 0.01);
  std::this_thread::sleep_for(3s);
  ASSERT_TRUE(server_a->running());
  server_a->Signal(SIGKILL);
  int code = -1;
  ASSERT_TRUE(server_a->Wait(30, &code));
  EXPECT_EQ(code, 128 + SIGKILL);
  std::this_thread::sleep_for(1500ms);
  auto server_b = StartServer("b");
  ASSERT_TRUE(device->Wait(120, &code)) << "device did not finish";
  EXPECT_EQ(code, 0) << device->Out();
  server_b->Signal(SIGTERM);
  ASSERT_TRUE(server_b->Wait(60, &code));
  EXPECT_EQ(code, 0) << server_b->Out();

  auto dev = ReadJsonNumbers(dir_ + "/device.json");
  EXPECT_EQ(dev["nonfinite_outputs"], 0);
  const auto rows = ReadTrace(dir_ + "/trace.csv");
  ASSERT_GT(rows.size(), 3000u);

  // The outage: the longest stretch of stale ticks (a loaded machine may stall the
  // server for ~100 ms now and then; the kill is the stretch of ~1.5 s).
  size_t first_stale = rows.size(), longest = 0;
  for (size_t i = 0; i < rows.size();) {
    if (rows[i].t_s > 1.0 && rows[i].model_age_ms > kTimeoutMs) {
      size_t j = i;
      while (j < rows.size() && rows[j].model_age_ms > kTimeoutMs) ++j;
      if (j - i > longest) {
        longest = j - i;
        first_stale = i;
      }
      i = j;
    } else {
      ++i;
    }
  }
  ASSERT_LT(first_stale, rows.size()) << "the device never noticed the killed server";
  // When the last model of server A arrived (device clock).
  const double t_last_model = rows[first_stale].t_s - 1e-3 * rows[first_stale].model_age_ms;
  // Just before the outage the device rendered a real force.
  double before = 0.0;
  for (size_t i = first_stale; i-- > 0 && rows[i].t_s > t_last_model - 0.2;) {
    before = std::max(before, rows[i].force_norm());
  }
  EXPECT_GT(before, 0.1) << "a force to fade";
  // The end of the outage: the first tick with a fresh model again (server B).
  size_t recovered = rows.size();
  for (size_t i = first_stale; i < rows.size(); ++i) {
    if (rows[i].model_age_ms >= 0.0 && rows[i].model_age_ms < kTimeoutMs) {
      recovered = i;
      break;
    }
  }
  ASSERT_LT(recovered, rows.size()) << "the device never got a model from the new server";
  const double outage_s = rows[recovered].t_s - t_last_model;
  EXPECT_GT(outage_s, 1.0) << "the outage lasts from the kill to server B's first model";

  // Faded to exactly zero within timeout + fade (+ 50 ms for late servo ticks on a loaded
  // machine: the fade runs on the device clock, a late tick only delays its sample) and
  // zero from then on until server B answered.
  const double deadline = t_last_model + 1e-3 * (kTimeoutMs + kFadeMs) + 0.050;
  size_t first_zero = rows.size();
  for (size_t i = first_stale; i < recovered; ++i) {
    if (rows[i].force_norm() == 0.0) {
      first_zero = i;
      break;
    }
  }
  ASSERT_LT(first_zero, recovered) << "the force never reached zero during the outage";
  EXPECT_LE(rows[first_zero].t_s, deadline)
      << "zero at " << rows[first_zero].t_s - t_last_model << " s after the last model";
  for (size_t i = first_zero; i < recovered; ++i) {
    ASSERT_EQ(rows[i].force_norm(), 0.0) << "force came back without a model at t = " << rows[i].t_s;
    ASSERT_EQ(rows[i].fading, 1);
  }
  // The fade never increased the force while stale.
  for (size_t i = first_stale + 1; i < first_zero; ++i) {
    EXPECT_LE(rows[i].force_norm(), rows[i - 1].force_norm() + 1e-9) << "t = " << rows[i].t_s;
  }

  // Recovery: fresh models and a real force again, after the fade-in.
  int fresh_with_force = 0;
  for (size_t i = recovered; i < rows.size(); ++i) {
    if (rows[i].fading == 0 && rows[i].model_age_ms < kTimeoutMs && rows[i].force_norm() > 0.05) {
      ++fresh_with_force;
    }
  }
  EXPECT_GT(fresh_with_force, 500) << "force did not recover after the new server started";
  auto srv_b = ReadJsonNumbers(dir_ + "/server_b.json");
  EXPECT_GT(srv_b["updates"], 500);
  std::printf("outage %.3f s; zero force %.1f ms after the last model (limit %d + %d ms); "
              "%d fresh ticks with force after recovery\n",
              outage_s, 1e3 * (rows[first_zero].t_s - t_last_model), kTimeoutMs, kFadeMs,
              fresh_with_force);
}

// thread3d with a constrained grip over real processes, driven along the scene's own path
// by sim-path: every model valid, finite forces, no chatter. (The grip mapping
// d = R(q) d_start itself is checked in server_messages_test.cc.)
TEST_F(ProcessTest, GripSceneFollowsWithoutChatter) {
  scene_path_ = source_ + "/scenes/thread3d_loop.yaml";
  scene_ = LoadScene(scene_path_);
  auto server = StartServer("a");
  auto device = StartDevice(5.0, "", 0.02);
  int code = -1;
  ASSERT_TRUE(device->Wait(120, &code)) << "device did not finish";
  EXPECT_EQ(code, 0) << device->Out();
  server->Signal(SIGTERM);
  ASSERT_TRUE(server->Wait(60, &code));
  EXPECT_EQ(code, 0) << server->Out();
  auto dev = ReadJsonNumbers(dir_ + "/device.json");
  auto srv = ReadJsonNumbers(dir_ + "/server_a.json");
  ASSERT_GT(dev.count("ticks"), 0u) << device->Out();
  EXPECT_GT(dev["models_received"], 0.5 * dev["ticks"]);
  EXPECT_EQ(dev["nonfinite_outputs"], 0);
  EXPECT_EQ(srv["invalid_models"], 0);
  EXPECT_LE(srv["snaps"], 10) << "the thread chatters";
  EXPECT_GT(dev["max_force_n"], 0.05);
}

// The server's command line: exit codes and messages that name the argument.
TEST_F(ProcessTest, ServerCommandLine) {
  const std::string server = bin_ + "/snapthread-server";
  auto run = [&](std::vector<std::string> args, int* code) {
    args.insert(args.begin(), server);
    ChildProcess c(args, LogTo(dir_ + "/cli.log"));
    EXPECT_TRUE(c.Wait(60, code));
    return c.Out();
  };
  int code = -1;
  std::string log = run({"--help"}, &code);
  EXPECT_EQ(code, 0);
  EXPECT_NE(log.find("--scene"), std::string::npos);
  EXPECT_NE(log.find("--shape-rate-hz"), std::string::npos);

  log = run({}, &code);
  EXPECT_EQ(code, 2);
  EXPECT_NE(log.find("--scene"), std::string::npos) << log;

  log = run({"--scene", dir_ + "/missing.yaml"}, &code);
  EXPECT_EQ(code, 2);
  EXPECT_NE(log.find("missing.yaml"), std::string::npos) << log;

  log = run({"--scene", scene_path_, "--method", "gradient-descent"}, &code);
  EXPECT_EQ(code, 2);
  EXPECT_NE(log.find("--method"), std::string::npos) << log;

  log = run({"--scene", scene_path_, "--shape-rate-hz", "0"}, &code);
  EXPECT_EQ(code, 2);
  EXPECT_NE(log.find("--shape-rate-hz"), std::string::npos) << log;

  log = run({"--scene", scene_path_, "--session", "bad session!"}, &code);
  EXPECT_EQ(code, 2);
  EXPECT_NE(log.find("--session"), std::string::npos) << log;

  log = run({"--scene", scene_path_, "--session", std::string(60, 'S')}, &code);
  EXPECT_EQ(code, 2);
  EXPECT_NE(log.find("--session"), std::string::npos) << log;

  log = run({"--scene", scene_path_, "--lcm-url", "udpm://300.1.2.3:7667"}, &code);
  EXPECT_EQ(code, 1);
  EXPECT_NE(log.find("udpm://300.1.2.3:7667"), std::string::npos) << log;
  EXPECT_NE(log.find("ip route add 224.0.0.0/4 dev lo"), std::string::npos) << log;

  // A clean timed run writes the summary with every key the demo reads.
  const std::string summary = dir_ + "/cli.json";
  log = run({"--scene", scene_path_, "--session", session_, "--lcm-url", kUrl, "--duration", "0.5",
             "--summary", summary},
            &code);
  EXPECT_EQ(code, 0) << log;
  const auto s = ReadJsonNumbers(summary);
  for (const char* key : {"updates", "update_rate_hz", "solve_us_p50", "solve_us_p99", "snaps",
                          "dropped_poses", "rejected_messages"}) {
    EXPECT_EQ(s.count(key), 1u) << key;
  }
  EXPECT_GT(s.at("shapes_published"), 5);  // 60 Hz for 0.5 s, even with no device
  EXPECT_NE(log.find("final: updates=0"), std::string::npos) << log;

  // --duration 0 runs until SIGINT, then stops cleanly.
  {
    ChildProcess c({server, "--scene", scene_path_, "--session", session_, "--lcm-url", kUrl},
            LogTo(dir_ + "/sigint.log"));
    ASSERT_TRUE(c.WaitForOutput("server: session", 30)) << c.Out();
    c.Signal(SIGINT);
    ASSERT_TRUE(c.Wait(30, &code));
    EXPECT_EQ(code, 0) << c.Out();
    EXPECT_NE(c.Out().find("final: updates=0"), std::string::npos) << c.Out();
  }
}

// deploy/run_demo.sh end to end (server + virtual-hand device, summary), short.
TEST_F(ProcessTest, RunDemoScript) {
  ChildProcess demo({"/bin/bash", source_ + "/deploy/run_demo.sh", "--bin-dir", bin_, "--duration", "3",
              "--out", dir_ + "/demo"},
             LogTo(dir_ + "/demo.log"));
  int code = -1;
  ASSERT_TRUE(demo.Wait(120, &code)) << demo.Out();
  const std::string log = demo.Out();
  EXPECT_EQ(code, 0) << log;
  for (const char* text : {"tick rate", "round trip", "snaps felt", "max force", "clamps",
                           "updates", "solve", "final log line: updates="}) {
    EXPECT_NE(log.find(text), std::string::npos) << text << " missing in\n" << log;
  }
  const auto dev = ReadJsonNumbers(dir_ + "/demo/device.json");
  const auto srv = ReadJsonNumbers(dir_ + "/demo/server.json");
  ASSERT_EQ(dev.count("models_received"), 1u) << log;
  EXPECT_GT(dev.at("models_received"), 1000);
  EXPECT_EQ(dev.at("nonfinite_outputs"), 0);
  EXPECT_GT(srv.at("updates"), 1000);

  // Bad arguments: exit 2 naming the argument.
  ChildProcess bad({"/bin/bash", source_ + "/deploy/run_demo.sh", "--bin-dir", bin_, "--duration", "x"},
            LogTo(dir_ + "/demo_bad.log"));
  ASSERT_TRUE(bad.Wait(60, &code));
  EXPECT_EQ(code, 2);
  EXPECT_NE(bad.Out().find("--duration"), std::string::npos) << bad.Out();
}

}  // namespace
}  // namespace snapthread::server
