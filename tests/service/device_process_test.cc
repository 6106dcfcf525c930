// snapthread-device as a real process against a fake server in this test process, over
// udpm on loopback with a unique session per test. The fake server answers every pose
// with the local model of a linear spring anchored at the device origin,
//   F(u) = -k u  ->  f0 = -k u0, K = -k I,
// which the device's local model reproduces exactly, so the trace's force must follow
// the spring law. The server is then killed (the force must fade to zero within the
// timeout + fade window), restarted (the force must come back), and malformed, oversized
// and NaN packets are thrown at the FORCE_MODEL channel (counted, dropped, no crash,
// no non-finite output).
#include <gtest/gtest.h>

#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "messages/channels.h"
#include "messages/subscribe.h"
#include "messages/validate.h"
#include "device_fake_server.h"
#include "test_support.h"

namespace snapthread::device {
namespace {

using testing::DeviceProcess;
using testing::FakeServer;
using testing::WriteDeviceScene;
using testing::kNegativeStiffnessNPerM;
using testing::kSpringNPerM;
constexpr const char* kUrl = test_support::kLoopbackLcmUrl;

using test_support::ReadFile;
using test_support::UniqueSession;

std::string DeviceBinary() { return test_support::BinDir() + "/snapthread-device"; }

// "key": number from the summary JSON (NaN when absent).
double JsonNumber(const std::string& json, const std::string& key) {
  const std::string k = "\"" + key + "\":";
  const size_t p = json.find(k);
  if (p == std::string::npos) return std::numeric_limits<double>::quiet_NaN();
  return std::strtod(json.c_str() + p + k.size(), nullptr);
}

struct TraceSample {
  double t_s, seq, x[3], f[3], model_age_ms;
  int model_status, clamped, fading;
};

std::vector<TraceSample> ReadTrace(const std::string& path, std::string* header) {
  std::ifstream in(path);
  std::vector<TraceSample> rows;
  std::string line;
  std::getline(in, line);
  *header = line;
  while (std::getline(in, line)) {
    TraceSample s{};
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%d,%d,%d", &s.t_s, &s.seq,
                    &s.x[0], &s.x[1], &s.x[2], &s.f[0], &s.f[1], &s.f[2], &s.model_age_ms,
                    &s.model_status, &s.clamped, &s.fading) == 12) {
      rows.push_back(s);
    }
  }
  return rows;
}

void SleepUntil(std::chrono::steady_clock::time_point t0, double s) {
  std::this_thread::sleep_until(t0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                         std::chrono::duration<double>(s)));
}

TEST(DeviceProcessTest, SpringFadeRecoveryAndBadPackets) {
  const test_support::SessionKeyFile key_file;  // SNAPTHREAD_KEY_FILE for the device
  const std::string bin = DeviceBinary();
  ASSERT_FALSE(bin.empty()) << "SNAPTHREAD_BIN_DIR not set (run through ctest)";
  const test_support::ScopedTempDir scoped("device_test");
  const std::string& dir = scoped.path();
  const std::string session = UniqueSession("DEVTEST_SPRING");
  const std::string scene = WriteDeviceScene(dir, "device_process_test");
  const messages::Channels channels(session);

  auto server = std::make_unique<FakeServer>(session, &key_file.key());
  ASSERT_TRUE(server->good()) << "udpm on loopback unavailable: " << kUrl;

  const double duration_s = 5.0;
  DeviceProcess device({bin, "--backend", "sim-path", "--scene", scene, "--session", session,
                  "--lcm-url", kUrl, "--duration", std::to_string(duration_s), "--speed-m-per-s",
                  "0.04", "--no-rt", "--log-level", "warn", "--trace", dir + "/trace.csv",
                  "--summary", dir + "/summary.json"},
                 dir + "/device");
  ASSERT_TRUE(device.started());
  const auto t0 = std::chrono::steady_clock::now();

  // 0 - 1.8 s: server up. 1.8 - 3.0 s: server dead. 3.0 s on: server back.
  SleepUntil(t0, 1.8);
  const int poses_first = server->poses();
  server.reset();
  SleepUntil(t0, 3.0);
  server = std::make_unique<FakeServer>(session, &key_file.key());
  ASSERT_TRUE(server->good());
  SleepUntil(t0, 3.6);

  // Bad packets on the FORCE_MODEL channel.
  lcm::LCM attacker(kUrl);
  ASSERT_TRUE(attacker.good());
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> byte(0, 255);
  int injected = 0;
  // Paced so that a burst does not overflow the socket buffer (that would test the
  // kernel, not the device).
  auto Pace = [] { std::this_thread::sleep_for(std::chrono::milliseconds(3)); };
  for (int i = 0; i < 40; ++i) {  // random garbage, some with the right type hash
    force_model_t ref{};
    std::vector<uint8_t> enc(ref.getEncodedSize());
    ref.encode(enc.data(), 0, static_cast<int>(enc.size()));
    size_t size = 1 + (i * 37) % 1000;
    if (i % 2 == 0 && size == enc.size()) ++size;  // never accidentally valid
    std::vector<uint8_t> buf(size);
    for (auto& b : buf) b = static_cast<uint8_t>(byte(rng));
    if (i % 2 == 0 && buf.size() >= 8) std::copy(enc.begin(), enc.begin() + 8, buf.begin());
    attacker.publish(channels.force_model, buf.data(), static_cast<unsigned>(buf.size()));
    ++injected;
    Pace();
  }
  for (int i = 0; i < 10; ++i) {  // NaN / Inf models
    force_model_t m{};
    m.status = force_model_t::STATUS_REGULAR;
    m.device_utime = 1;
    if (i % 3 == 0) m.f0[i % 3] = std::numeric_limits<double>::quiet_NaN();
    if (i % 3 == 1) m.K[1][1] = std::numeric_limits<double>::infinity();
    if (i % 3 == 2) m.u0[2] = -std::numeric_limits<double>::infinity();
    attacker.publish(channels.force_model, &m);
    ++injected;
    Pace();
  }
  for (int i = 0; i < 10; ++i) {  // oversized: a valid spring model plus trailing bytes
    force_model_t m{};
    m.status = force_model_t::STATUS_REGULAR;
    std::vector<uint8_t> enc(m.getEncodedSize() + 64, 0x5A);
    m.encode(enc.data(), 0, m.getEncodedSize());
    attacker.publish(channels.force_model, enc.data(), static_cast<unsigned>(enc.size()));
    ++injected;
    Pace();
  }
  for (int i = 0; i < 2; ++i) {  // huge: 100 kB (fragmented by LCM)
    std::vector<uint8_t> big(100000, static_cast<uint8_t>(0xA0 + i));
    attacker.publish(channels.force_model, big.data(), static_cast<unsigned>(big.size()));
    ++injected;
    Pace();
  }

  const int code = device.ExitCode(duration_s + 20.0);
  const int poses_second = server->poses();
  server.reset();
  ASSERT_EQ(code, 0) << device.Err();

  const std::string summary = ReadFile(dir + "/summary.json");
  ASSERT_FALSE(summary.empty());
  for (const char* key : {"ticks", "tick_rate_hz", "lateness_us_p50", "lateness_us_p99",
                          "lateness_us_max", "round_trip_us_p50", "round_trip_us_p99",
                          "models_received", "models_rejected", "poses_rejected", "force_clamps",
                          "stiffness_clamps", "slew_limits", "fade_ticks", "snaps_felt",
                          "max_force_n", "nonfinite_outputs"}) {
    EXPECT_TRUE(std::isfinite(JsonNumber(summary, key))) << key << "\n" << summary;
  }
  // The loop ran (its rate is DeviceServoLoopTest's business; this machine is shared and
  // without SCHED_FIFO a loaded run has been seen at 500 Hz).
  EXPECT_GT(JsonNumber(summary, "ticks"), 0.2 * 1000 * duration_s) << summary;
  EXPECT_GT(poses_first, 300);
  EXPECT_GT(poses_second, 300);
  // Models arrived and the round trip was measured.
  EXPECT_GT(JsonNumber(summary, "models_received"), 500) << summary;
  const double rt50 = JsonNumber(summary, "round_trip_us_p50");
  EXPECT_GT(rt50, 0.0) << summary;
  EXPECT_LT(rt50, 1e6) << summary;
  EXPECT_GE(JsonNumber(summary, "round_trip_us_p99"), rt50) << summary;
  // Bad packets: counted and dropped (udpm on loopback may lose a few), and the device
  // never output a non-finite force. Besides them only the few models that answer poses
  // sent before the device heard a (re)started server's signed status are refused
  // (another epoch than the pose's): at most a status period's worth at each start.
  const double rejected = JsonNumber(summary, "models_rejected");
  EXPECT_GE(rejected, 0.8 * injected) << summary;
  EXPECT_LE(rejected, injected + 2 * 50) << summary;
  EXPECT_EQ(JsonNumber(summary, "nonfinite_outputs"), 0.0) << summary;
  EXPECT_GT(JsonNumber(summary, "fade_ticks"), 200) << summary;
  // Every accepted model had its negative z stiffness clamped; about 1 in 100 snapped.
  const double received = JsonNumber(summary, "models_received");
  EXPECT_EQ(JsonNumber(summary, "stiffness_clamps"), received) << summary;
  EXPECT_GE(JsonNumber(summary, "snaps_felt"), std::floor(0.5 * received / 100)) << summary;
  EXPECT_LE(JsonNumber(summary, "snaps_felt"), std::ceil(received / 100) + 2) << summary;

  std::string header;
  const auto rows = ReadTrace(dir + "/trace.csv", &header);
  EXPECT_EQ(header, "t_s,seq,x_m,y_m,z_m,fx_n,fy_n,fz_n,model_age_ms,model_status,clamped,fading,"
                    "qw,qx,qy,qz,tx_nm,ty_nm,tz_nm");
  ASSERT_GT(rows.size(), 1000u);

  // Spring law on every settled sample: a fresh model, and no stale tick (fading or no
  // model) within the last fade time, so the fade gain is back at 1. (A starved fake
  // server on a loaded machine makes short fades in the middle of the run too.)
  const double timeout_ms = 50.0, fade_ms = 100.0;
  int settled = 0, lawful = 0;
  double last_unsettled_t = 0.0;
  for (const auto& r : rows) {
    if (r.model_age_ms < 0.0 || r.fading) {
      last_unsettled_t = r.t_s;
      continue;
    }
    if (r.model_age_ms > 20.0 || r.t_s - last_unsettled_t < 1e-3 * fade_ms + 0.005) continue;
    ++settled;
    double err2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double e = r.f[k] - (-kSpringNPerM * r.x[k]);
      err2 += e * e;
    }
    if (std::sqrt(err2) < 1e-3) ++lawful;
  }
  EXPECT_GT(settled, 500);
  EXPECT_GE(lawful, 0.99 * settled) << lawful << " of " << settled;

  // Fade: once the model is older than timeout + fade (+ a tick), the force is exactly 0;
  // between timeout and that, the device says it is fading.
  int dead = 0, dead_nonzero = 0, fading_flagged = 0, fading_window = 0;
  size_t last_dead = 0;
  double first_dead_t = -1.0, last_dead_t = -1.0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    const double fn = std::sqrt(r.f[0] * r.f[0] + r.f[1] * r.f[1] + r.f[2] * r.f[2]);
    if (r.model_age_ms > timeout_ms + fade_ms + 2.0) {
      ++dead;
      last_dead = i;
      if (first_dead_t < 0.0) first_dead_t = r.t_s;
      last_dead_t = r.t_s;
      if (fn != 0.0) ++dead_nonzero;
    } else if (r.model_age_ms > timeout_ms + 1.0) {
      ++fading_window;
      if (r.fading) ++fading_flagged;
    }
  }
  // The server was away 1.2 s: about 1.05 s of it past timeout + fade.
  EXPECT_GT(dead, 100);
  EXPECT_GT(last_dead_t - first_dead_t, 0.7) << "stale-model span " << first_dead_t << " - " << last_dead_t;
  EXPECT_EQ(dead_nonzero, 0);
  EXPECT_GT(fading_window, 20);
  EXPECT_EQ(fading_flagged, fading_window);

  // Recovery after the restart: fresh models again and the spring felt again.
  int recovered = 0;
  for (size_t i = last_dead + 1; i < rows.size(); ++i) {
    const auto& r = rows[i];
    const double fn = std::sqrt(r.f[0] * r.f[0] + r.f[1] * r.f[1] + r.f[2] * r.f[2]);
    if (r.model_age_ms >= 0.0 && r.model_age_ms < 20.0 && fn > 0.05) ++recovered;
  }
  EXPECT_GT(recovered, 200);
}

// Listens to a session's device poses and statuses.
class Listener {
 public:
  explicit Listener(const std::string& session) : channels_(session), lcm_(kUrl) {
    if (!lcm_.good()) return;
    messages::Subscribe<&Listener::OnPose>(lcm_, channels_.device_state, this);
    messages::Subscribe<&Listener::OnStatus>(lcm_, channels_.device_status, this);
    thread_ = std::thread([this] {
      while (!stop_.load()) lcm_.handleTimeout(10);
    });
  }
  ~Listener() { Stop(); }
  void Stop() {
    stop_.store(true);
    if (thread_.joinable()) thread_.join();
  }
  bool good() { return lcm_.good(); }
  int poses = 0, seq_gaps = 0, statuses = 0, bad = 0;
  int64_t first_seq = -1, last_seq = -1;
  device_status_t last_status{};

 private:
  void OnPose(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    device_state_t m;
    if (!messages::DecodeAndValidate(rbuf, &m, nullptr)) {
      ++bad;
      return;
    }
    if (first_seq < 0) first_seq = m.seq;
    if (last_seq >= 0 && m.seq != last_seq + 1) ++seq_gaps;
    last_seq = m.seq;
    ++poses;
  }
  void OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    device_status_t m;
    if (!messages::DecodeAndValidate(rbuf, &m, nullptr)) {
      ++bad;
      return;
    }
    last_status = m;
    ++statuses;
  }
  messages::Channels channels_;
  lcm::LCM lcm_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
};

TEST(DeviceProcessTest, SigtermStopsCleanlyAndPublishesPosesAndStatus) {
  const test_support::SessionKeyFile key_file;  // SNAPTHREAD_KEY_FILE for the device
  const std::string bin = DeviceBinary();
  ASSERT_FALSE(bin.empty());
  const test_support::ScopedTempDir scoped("device_test");
  const std::string& dir = scoped.path();
  const std::string session = UniqueSession("DEVTEST_TERM");
  Listener listener(session);
  ASSERT_TRUE(listener.good());
  const std::string scene = WriteDeviceScene(dir, "device_process_test");
  DeviceProcess device({bin, "--backend", "virtual-hand", "--scene", scene, "--session", session,
                        "--lcm-url", kUrl, "--duration", "0", "--no-rt", "--publish-divisor", "4",
                        "--summary", dir + "/summary.json"},
                       dir + "/device");
  ASSERT_TRUE(device.started());
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  device.Signal(SIGTERM);
  ASSERT_EQ(device.ExitCode(10.0), 0) << device.Err();
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  listener.Stop();
  const std::string summary = ReadFile(dir + "/summary.json");
  const double ticks = JsonNumber(summary, "ticks");
  EXPECT_GT(ticks, 500) << summary;
  EXPECT_EQ(JsonNumber(summary, "models_received"), 0.0) << summary;  // no server
  EXPECT_EQ(JsonNumber(summary, "nonfinite_outputs"), 0.0);
  // Every 4th pose is published, numbered consecutively from 0.
  EXPECT_EQ(listener.bad, 0);
  EXPECT_GT(listener.poses, 0.8 * ticks / 4) << listener.poses << " poses, " << ticks << " ticks";
  EXPECT_LE(listener.poses, ticks / 4 + 1);
  EXPECT_EQ(listener.first_seq, 0);
  EXPECT_LE(listener.seq_gaps, 3);  // udpm may drop a datagram now and then
  // DEVICE_STATUS at ~2 Hz over the device's own run (its start-up is part of the 2.5 s,
  // and takes longer in a sanitized build).
  const double run_s = JsonNumber(summary, "duration_s");
  EXPECT_GE(listener.statuses, std::max(1, static_cast<int>(2.0 * run_s) - 2)) << summary;
  EXPECT_LE(listener.statuses, static_cast<int>(2.0 * run_s) + 3) << summary;
  EXPECT_GT(listener.last_status.ticks, 200);
  EXPECT_GT(listener.last_status.tick_rate_hz, 100.0);
  EXPECT_LE(listener.last_status.tick_rate_hz, 1100.0);
  EXPECT_EQ(listener.last_status.models_received, 0);
  EXPECT_EQ(listener.last_status.device_id, "virtual-hand");
}

TEST(DeviceProcessTest, BadArgumentsExitTwoNamingTheArgument) {
  const test_support::SessionKeyFile key_file;  // SNAPTHREAD_KEY_FILE for the device
  const std::string bin = DeviceBinary();
  ASSERT_FALSE(bin.empty());
  const test_support::ScopedTempDir scoped("device_test");
  const std::string& dir = scoped.path();
  const std::string scene = WriteDeviceScene(dir, "device_process_test");
  struct Case {
    std::vector<std::string> args;
    std::string mention;
  };
  const std::vector<Case> cases = {
      {{"--rate-hz", "5"}, "--rate-hz"},
      {{"--backend", "joystick"}, "--backend"},
      {{"--session", "bad name"}, "--session"},
      {{"--scene", dir + "/missing.yaml"}, "--scene"},
      {{"--publish-divisor", "0"}, "--publish-divisor"},
      {{"--backend", "sim-path"}, "path"},  // no --scene / --path-csv
      {{"--backend", "phantom", "--no-rt"}, "not built"},
      {{"--backend", "delta", "--no-rt"}, "not built"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> args = {bin};
    args.insert(args.end(), c.args.begin(), c.args.end());
    DeviceProcess p(args, dir + "/bad");
    ASSERT_TRUE(p.started());
    EXPECT_EQ(p.ExitCode(10.0), 2) << c.args[0] << " " << c.args[1];
    const std::string msg = p.Err() + p.Out();
    EXPECT_NE(msg.find(c.mention), std::string::npos) << msg;
  }
}

TEST(DeviceProcessTest, LcmFailureExitsOneWithUrlAndHint) {
  const test_support::SessionKeyFile key_file;  // SNAPTHREAD_KEY_FILE for the device
  const std::string bin = DeviceBinary();
  ASSERT_FALSE(bin.empty());
  const test_support::ScopedTempDir scoped("device_test");
  const std::string& dir = scoped.path();
  const std::string url = "udpm://239.255.76.67:99999999?ttl=0";
  const std::string scene = WriteDeviceScene(dir, "device_process_test");
  DeviceProcess p({bin, "--backend", "sim-path", "--scene", scene, "--lcm-url", url, "--no-rt",
                   "--duration", "1"},
                  dir + "/lcmfail");
  ASSERT_TRUE(p.started());
  EXPECT_EQ(p.ExitCode(10.0), 1);
  const std::string err = p.Err();
  EXPECT_NE(err.find(url), std::string::npos) << err;
  EXPECT_NE(err.find("ip route add 224.0.0.0/4 dev lo"), std::string::npos) << err;
}

}  // namespace
}  // namespace snapthread::device
