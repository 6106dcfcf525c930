// A flood of forgeries against a genuine session, with real processes over udpm loopback:
// snapthread-server and snapthread-device (virtual-hand on the planar curve2d_snap scene)
// run a session on the root key; then forgers (tools/bench/flood_forger.h) of every kind
// at once send forged messages on every session channel where their role may not speak —
// valid encodings, tags made with no key of the session, with this session's observer,
// another device's or an operator's credential, or with another session's root key
// (learning the genuine epoch where they can), force models asking for 1000 N along z —
// for a few seconds, then stop. Asserted, with no rate
// threshold a slow machine could break (counts per second are divided by
// SNAPTHREAD_SPEED_SCALE):
//   * the device keeps admitting genuine models during and after the flood, and the
//     server keeps updating;
//   * the forged messages are refused and counted (the device's and the server's
//     rejection counts grow during the flood, by at least a few hundred), and the
//     forged commands change nothing (the server reports one scene throughout): 0
//     accepted where the role may not speak;
//   * no forged force reaches the hand: on the planar scene every genuine force has
//     z = 0, so the rendered z-force is 0 at every traced tick, and |F| never exceeds
//     the scene's max_force_n.
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "auth/key_set.h"
#include "auth/role_keys.h"
#include "auth/sealed_message.h"
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

// The genuine device's and server's statuses, as the root key's holder sees them: decoded,
// checked (the device's MAC under the key of device "hand", the server's signature and
// role; forged statuses of the flood are skipped), latest values kept.
class StatusWatch {
 public:
  StatusWatch(const std::string& session, const auth::SessionKey& root)
      : channels_(session), device_(auth::KeySet::ForRole(root, auth::Role::kDevice, "hand")) {
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
    std::string refusals;  // the server's last "role/reason=count" list
  };
  Snapshot Now() {
    std::lock_guard<std::mutex> lock(mutex_);
    return now_;
  }

 private:
  void OnDevice(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    device_status_t st;
    if (!messages::DecodeAndValidate(rbuf, &st, nullptr) || st.sender_name != device_.name() ||
        !auth::VerifyMac(rbuf->data, rbuf->data_size, channel, *device_.mac_key())) {
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    ++now_.device_statuses;
    now_.models_received = st.models_received;
    now_.models_rejected = st.models_rejected;
    now_.max_status_force_n = std::max(now_.max_status_force_n, st.force_norm_n);
  }
  void OnServer(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    solver_status_t st;
    if (!messages::DecodeAndValidate(rbuf, &st, nullptr) ||
        st.sender_role != static_cast<int8_t>(auth::Role::kServer) ||
        !auth::VerifySignature(rbuf->data, rbuf->data_size, channel, device_.server_public_key())) {
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    ++now_.server_statuses;
    now_.updates = st.updates;
    now_.server_rejected = st.rejected_messages;
    now_.refusals = st.refusals;
    if (now_.scenes.find(st.scene + ";") == std::string::npos) now_.scenes += st.scene + ";";
  }

  messages::Channels channels_;
  const auth::KeySet device_;
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

// `sealed`: the server and the device run with --encrypt ($SNAPTHREAD_ENCRYPT=1, which the
// children inherit) and this process opens their envelopes with the session's read key;
// the forgers send in clear as before, and those holding a credential could seal too.
void RunFloodAttack(bool sealed) {
  const SessionKeyFile key_file;  // SNAPTHREAD_KEY_FILE for both binaries
  if (sealed) {
    ::setenv("SNAPTHREAD_ENCRYPT", "1", 1);
    auth::SetSealing(auth::DeriveReadKey(key_file.key()), nullptr, /*seal_outgoing=*/false);
  }
  struct Unseal {
    ~Unseal() {
      ::unsetenv("SNAPTHREAD_ENCRYPT");
      auth::ClearSealing();
    }
  } unseal;
  const ScopedTempDir tmp("flood");
  const std::string dir = tmp.path();
  const std::string bin = BinDir();
  const std::string session = UniqueSession("FLOOD");
  const std::string scene = ScenePath("curve2d_snap.yaml");
  const double scale = SpeedScale();

  StatusWatch watch(session, key_file.key());
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

  // 2. The flood: every kind of forger at once, 3000 messages/s per channel in all.
  const flood::ForgerKind kinds[] = {flood::ForgerKind::kNoKey, flood::ForgerKind::kObserver,
                                     flood::ForgerKind::kOtherDevice, flood::ForgerKind::kOperator,
                                     flood::ForgerKind::kOtherSessionRoot};
  std::vector<std::unique_ptr<flood::ForgedFlood>> forgers;
  for (const flood::ForgerKind kind : kinds) {
    flood::ForgerOptions options;
    options.lcm_url = kUrl;
    options.session = session;
    options.rate_per_channel_hz = 3000.0 / std::size(kinds);
    options.forged_force_n = 1000.0;
    options.kind = kind;
    options.root_key_path = key_file.path();
    forgers.push_back(std::make_unique<flood::ForgedFlood>(options));
  }
  for (auto& forger : forgers) {
    std::string error;
    ASSERT_TRUE(forger->Start(&error)) << error;
  }
  std::this_thread::sleep_for(std::chrono::duration<double>(kPhaseSeconds));
  double sent = 0.0, achieved = 0.0;
  uint64_t failures = 0;
  for (size_t k = 0; k < forgers.size(); ++k) {
    forgers[k]->Stop();
    EXPECT_GT(forgers[k]->sent(), 100u) << flood::ForgerKindName(kinds[k]) << " sent almost nothing";
    sent += static_cast<double>(forgers[k]->sent());
    achieved += forgers[k]->AchievedRatePerChannel();
    failures += forgers[k]->failures();
  }
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

  std::printf("flood: %.0f forged messages sent (%.0f/s per channel); device models admitted %lld before, "
              "+%lld during, +%lld after; rejected +%lld during; server updates +%lld during, +%lld after, "
              "rejected +%lld during\n",
              sent, achieved, static_cast<long long>(before.models_received),
              static_cast<long long>(during.models_received - before.models_received),
              static_cast<long long>(after.models_received - flood_end.models_received),
              static_cast<long long>(flood_end.models_rejected - before.models_rejected),
              static_cast<long long>(during.updates - before.updates),
              static_cast<long long>(after.updates - flood_end.updates),
              static_cast<long long>(flood_end.server_rejected - before.server_rejected));
  std::printf("flood: the server's refusals: %s\n", after.refusals.c_str());
  ASSERT_GT(sent, 1000.0) << "the forgers sent almost nothing (" << failures << " publish failures)";
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

TEST(FloodAttackTest, GenuineSessionKeepsItsModelsAndNoForgedForceReachesTheHand) { RunFloodAttack(false); }

// The same attack on a sealed session (--encrypt): the seal changes nothing of the above.
TEST(FloodAttackTest, SealedSessionKeepsItsModelsAndNoForgedForceReachesTheHand) { RunFloodAttack(true); }

}  // namespace
}  // namespace snapthread
