// A keyless flood against a genuine session, with real processes over udpm loopback:
// snapthread-server and snapthread-device (virtual-hand on the planar curve2d_snap scene)
// run a session; then a forger (tools/bench/flood_forger.h) sends forged messages on
// every session channel — valid encodings, MACs under a key of its own, force models
// asking for 1000 N along z — for a few seconds, then stops. Asserted, with no rate
// threshold a slow machine could break (counts per second are divided by
// SNAPTHREAD_SPEED_SCALE):
//   * the device keeps admitting genuine models during and after the flood, and the
//     server keeps updating;
//   * the forged messages are refused and counted (the device's and the server's
//     rejection counts grow during the flood, by at least a few hundred), and the
//     forged commands change nothing (the server reports one scene throughout);
//   * no forged force reaches the hand: on the planar scene every genuine force has
//     z = 0, so the rendered z-force is 0 at every traced tick, and |F| never exceeds
//     the scene's max_force_n.
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "auth/message_mac.h"
#include "flood_forger.h"
#include "messages/channels.h"
#include "messages/subscribe.h"
#include "messages/validate.h"
#include "snapthread/device_status_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "test_support.h"

namespace snapthread {
namespace {

using namespace test_support;
using Clock = std::chrono::steady_clock;
// A multicast group and port of this test alone: the flood would otherwise fill the socket
// buffers of every other test's processes on the shared group (they would lose datagrams).
constexpr const char* kUrl = "udpm://239.255.76.92:7692?ttl=0";
constexpr double kPhaseSeconds = 3.0;
constexpr double kSceneMaxForceN = 3.0;  // scenes/curve2d_snap.yaml device.max_force_n

// The genuine device's and server's statuses, as a key holder sees them: decoded, MAC
// checked (forged statuses of the flood are skipped), latest values kept.
class StatusWatch {
 public:
  StatusWatch(const std::string& session, const auth::SessionKey* key) : channels_(session), key_(key) {
    // messages::Subscribe, not lcm::LCM::subscribe's member-function overload: GCC 12's
    // sanitizer build miscompiles that call (common/messages/subscribe.h).
    messages::Subscribe<&StatusWatch::OnDevice>(lcm_, channels_.device_status, this);
    messages::Subscribe<&StatusWatch::OnServer>(lcm_, channels_.solver_status, this);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(10);
    });
  }
  ~StatusWatch() {
    stop_ = true;
    thread_.join();
  }
  bool good() { return lcm_.good(); }

  struct Snapshot {
    int64_t device_statuses = 0, models_received = 0, models_rejected = 0;
    int64_t server_statuses = 0, updates = 0, server_rejected = 0;
    double max_status_force_n = 0.0;
    std::string scenes;  // every scene name the genuine server reported, ';'-separated
  };
  Snapshot Now() {
    std::lock_guard<std::mutex> lock(mutex_);
    return now_;
  }

 private:
  bool Genuine(const lcm::ReceiveBuffer* rbuf, const std::string& channel) const {
    return auth::VerifyEncoded(rbuf->data, rbuf->data_size, channel, *key_);
  }
  void OnDevice(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    device_status_t st;
    if (!messages::DecodeAndValidate(rbuf, &st, nullptr) || !Genuine(rbuf, channel)) return;
    std::lock_guard<std::mutex> lock(mutex_);
    ++now_.device_statuses;
    now_.models_received = st.models_received;
    now_.models_rejected = st.models_rejected;
    now_.max_status_force_n = std::max(now_.max_status_force_n, st.force_norm_n);
  }
  void OnServer(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    solver_status_t st;
    if (!messages::DecodeAndValidate(rbuf, &st, nullptr) || !Genuine(rbuf, channel)) return;
    std::lock_guard<std::mutex> lock(mutex_);
    ++now_.server_statuses;
    now_.updates = st.updates;
    now_.server_rejected = st.rejected_messages;
    if (now_.scenes.find(st.scene + ";") == std::string::npos) now_.scenes += st.scene + ";";
  }

  messages::Channels channels_;
  const auth::SessionKey* key_;
  lcm::LCM lcm_{kUrl};
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::mutex mutex_;
  Snapshot now_;
};

// Rendered force over the device's --trace: max |F| and max |F_z|; rows counted.
struct TraceForces {
  long rows = 0;
  double max_force_n = 0.0, max_abs_fz_n = 0.0;
};
TraceForces ReadTraceForces(const std::string& path) {
  TraceForces t;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header: t_s,seq,x_m,y_m,z_m,fx_n,fy_n,fz_n,...
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string cell;
    double f[8];
    int k = 0;
    while (k < 8 && std::getline(ss, cell, ',')) f[k++] = std::strtod(cell.c_str(), nullptr);
    if (k < 8) continue;
    ++t.rows;
    t.max_force_n = std::max(t.max_force_n, std::sqrt(f[5] * f[5] + f[6] * f[6] + f[7] * f[7]));
    t.max_abs_fz_n = std::max(t.max_abs_fz_n, std::fabs(f[7]));
  }
  return t;
}

TEST(FloodAttackTest, GenuineSessionKeepsItsModelsAndNoForgedForceReachesTheHand) {
  const SessionKeyFile key_file;  // SNAPTHREAD_KEY_FILE for both binaries
  const ScopedTempDir tmp("flood");
  const std::string dir = tmp.path();
  const std::string bin = BinDir();
  const std::string session = UniqueSession("FLOOD");
  const std::string scene = ScenePath("curve2d_snap.yaml");
  const double scale = SpeedScale();

  StatusWatch watch(session, &key_file.key());
  ASSERT_TRUE(watch.good());
  ChildProcess server({bin + "/snapthread-server", "--scene", scene, "--session", session, "--lcm-url", kUrl,
                       "--duration", "200", "--summary", dir + "/server.json", "--log-level", "info"},
                      OneLog(dir + "/server.txt"));
  ASSERT_TRUE(server.started());
  ASSERT_TRUE(server.WaitForOutput("server: session", 30.0 * scale)) << server.Out();
  ChildProcess device({bin + "/snapthread-device", "--backend", "virtual-hand", "--scene", scene, "--session",
                       session, "--lcm-url", kUrl, "--duration", "0", "--no-rt", "--summary",
                       dir + "/device.json", "--trace", dir + "/trace.csv", "--log-level", "info"},
                      OneLog(dir + "/device.txt"));
  ASSERT_TRUE(device.started());

  // 1. The genuine session runs: the device reports admitted models.
  ASSERT_TRUE(WaitUntil([&] { return watch.Now().models_received > 0; }, 30.0 * scale))
      << "no genuine model reached the device before the flood\n"
      << device.Out();
  std::this_thread::sleep_for(std::chrono::duration<double>(1.0));
  const auto before = watch.Now();

  // 2. The flood.
  flood::ForgerOptions options;
  options.lcm_url = kUrl;
  options.session = session;
  options.rate_per_channel_hz = 3000.0;
  options.forged_force_n = 1000.0;
  flood::ForgedFlood forger(options);
  std::string error;
  ASSERT_TRUE(forger.Start(&error)) << error;
  std::this_thread::sleep_for(std::chrono::duration<double>(kPhaseSeconds));
  forger.Stop();
  const auto during = watch.Now();
  // Statuses come at ~2 Hz (device) and ~10 Hz (server): let the last flood second in.
  std::this_thread::sleep_for(std::chrono::duration<double>(1.0));
  const auto flood_end = watch.Now();

  // 3. After the flood.
  std::this_thread::sleep_for(std::chrono::duration<double>(kPhaseSeconds));
  const auto after = watch.Now();

  device.Signal(SIGTERM);
  int code = -1;
  ASSERT_TRUE(device.Wait(30.0 * scale, &code)) << device.Out();
  EXPECT_EQ(code, 0) << device.Out();
  server.Signal(SIGTERM);
  ASSERT_TRUE(server.Wait(30.0 * scale, &code)) << server.Out();

  const double sent = static_cast<double>(forger.sent());
  std::printf("flood: %.0f forged messages sent (%.0f/s per channel); device models admitted %lld before, "
              "+%lld during, +%lld after; rejected +%lld during; server updates +%lld during, +%lld after, "
              "rejected +%lld during\n",
              sent, forger.AchievedRatePerChannel(), static_cast<long long>(before.models_received),
              static_cast<long long>(during.models_received - before.models_received),
              static_cast<long long>(after.models_received - flood_end.models_received),
              static_cast<long long>(flood_end.models_rejected - before.models_rejected),
              static_cast<long long>(during.updates - before.updates),
              static_cast<long long>(after.updates - flood_end.updates),
              static_cast<long long>(flood_end.server_rejected - before.server_rejected));
  ASSERT_GT(sent, 1000.0) << "the forger sent almost nothing (" << forger.failures() << " publish failures)";
  const double min_models = 20.0 * kPhaseSeconds / scale;  // genuine models run at ~1 kHz
  EXPECT_GE(during.models_received - before.models_received, min_models)
      << "the device stopped admitting genuine models during the flood";
  EXPECT_GE(after.models_received - flood_end.models_received, min_models)
      << "the device did not recover its genuine models after the flood";
  EXPECT_GE(during.updates - before.updates, min_models) << "the server stopped updating during the flood";
  EXPECT_GE(after.updates - flood_end.updates, min_models) << "the server did not recover after the flood";

  // Refused and counted: forged force models on the device, forged poses and commands on
  // the server (a few hundred at least of the ~9,000 per channel sent; UDP may drop some).
  EXPECT_GE(flood_end.models_rejected - before.models_rejected, 300) << "forged models not counted as rejected";
  EXPECT_GE(flood_end.server_rejected - before.server_rejected, 300) << "forged poses/commands not counted";
  EXPECT_EQ(before.models_rejected, 0) << "refusals before any forgery";
  const auto device_summary = ReadJsonNumbers(dir + "/device.json");
  EXPECT_GE(device_summary.at("models_rejected"), static_cast<double>(flood_end.models_rejected));
  EXPECT_NE(device.Out().find("bad MAC"), std::string::npos) << "the device did not log the refusals";
  // The forged LOAD_SCENE commands changed nothing: one scene all along.
  EXPECT_EQ(after.scenes.find(';'), after.scenes.size() - 1) << "scenes reported: " << after.scenes;
  EXPECT_EQ(after.scenes.find("forged"), std::string::npos) << after.scenes;

  // No forged force on the hand.
  const TraceForces forces = ReadTraceForces(dir + "/trace.csv");
  std::printf("flood: %ld traced ticks, max |F| %.3f N, max |F_z| %g N\n", forces.rows, forces.max_force_n,
              forces.max_abs_fz_n);
  EXPECT_GT(forces.rows, 1000) << "trace too short";
  EXPECT_EQ(forces.max_abs_fz_n, 0.0) << "a z-force was rendered: forged models reached the output";
  EXPECT_LE(forces.max_force_n, kSceneMaxForceN + 1e-9);
  EXPECT_LE(device_summary.at("max_force_n"), kSceneMaxForceN + 1e-9);
  EXPECT_LE(after.max_status_force_n, kSceneMaxForceN + 1e-9);
  EXPECT_GT(forces.max_force_n, 0.0) << "the genuine session rendered no force at all";
}

}  // namespace
}  // namespace snapthread
