// Issue 12 "Done when", with real processes over udpm loopback: a rogue without the key
// (snapthread-rogue, rogue.cc) forges force models answering the device's poses at 2 kHz,
// replays a logged genuine session (recorded here with lcm-logger first) and sends
// forged poses and commands (LOAD_SCENE /etc/passwd, LOAD_SCENE /dev/zero, SET_METHOD
// newton). A lone device renders nothing and counts the refusals; a lone server answers
// no forged pose, keeps its scene and method and its status flowing; a genuine device
// then gets its models.
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "auth/freshness_filter.h"
#include "auth/key_set.h"
#include "auth/message_gate.h"
#include "auth/message_mac.h"
#include "messages/channels.h"
#include "messages/subscribe.h"
#include "messages/validate.h"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "test_support.h"

namespace snapthread {
namespace {

using namespace test_support;
using Clock = std::chrono::steady_clock;
constexpr const char* kUrl = kLoopbackLcmUrl;

double JsonNumber(const std::string& json, const std::string& key) {
  const std::string k = "\"" + key + "\":";
  const size_t p = json.find(k);
  if (p == std::string::npos) return std::numeric_limits<double>::quiet_NaN();
  return std::strtod(json.c_str() + p + k.size(), nullptr);
}

// Watches the genuine server as the root key's holder would: statuses signed by the server
// with a fresh sequence (the epoch adopted from them), their gaps, scene and method; force
// models of that epoch with a valid MAC under the key of device "hand" (the scene's only
// grasp, which the device given the root key acts as). Exclude(epoch) ignores a recorded session's epoch: its
// statuses and models carry valid MACs, so the rogue's replay of them would otherwise be
// taken for the live server (a watcher started before the live server's first status
// adopts the replayed epoch; the sanitized build's slower start showed it).
class Watcher {
 public:
  Watcher(const std::string& session, const auth::SessionKey& root)
      : channels_(session), device_(auth::KeySet::ForRole(root, auth::Role::kDevice, "hand")) {
    messages::Subscribe<&Watcher::OnStatus>(lcm_, channels_.solver_status, this);
    messages::Subscribe<&Watcher::OnModel>(lcm_, channels_.force_model, this);
    thread_ = std::thread([this] {
      while (!stop_) lcm_.handleTimeout(10);
    });
  }
  ~Watcher() {
    stop_ = true;
    thread_.join();
  }
  bool good() { return lcm_.good(); }
  void Exclude(int64_t epoch) { excluded_epoch_.store(epoch); }
  int64_t epoch() const { return status_filter_.epoch(); }
  // Resets the gap measurement and the model count (a new phase).
  void Mark() {
    std::lock_guard<std::mutex> lock(mutex_);
    genuine_models_ = 0;
    max_gap_s_ = 0.0;
    last_status_ = Clock::time_point{};
  }
  int64_t genuine_models() {
    std::lock_guard<std::mutex> lock(mutex_);
    return genuine_models_;
  }
  double max_gap_s() {
    std::lock_guard<std::mutex> lock(mutex_);
    const double since = last_status_ == Clock::time_point{}
                             ? 1e9
                             : std::chrono::duration<double>(Clock::now() - last_status_).count();
    return std::max(max_gap_s_, since);
  }
  int64_t statuses() {
    std::lock_guard<std::mutex> lock(mutex_);
    return statuses_;
  }
  std::string scenes_and_methods() {
    std::lock_guard<std::mutex> lock(mutex_);
    return seen_;
  }

 private:
  void OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    solver_status_t st;
    if (!messages::DecodeAndValidate(rbuf, &st, nullptr)) return;
    if (st.epoch == excluded_epoch_.load()) return;
    if (auth::AdmitSigned(rbuf->data, rbuf->data_size, st, channel, device_.server_public_key(),
                          &status_filter_) != auth::Reason::kAccepted) {
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    const auto now = Clock::now();
    if (last_status_ != Clock::time_point{}) {
      max_gap_s_ = std::max(max_gap_s_, std::chrono::duration<double>(now - last_status_).count());
    }
    last_status_ = now;
    ++statuses_;
    const std::string sm = st.scene + "/" + st.method + ";";
    if (seen_.find(sm) == std::string::npos) seen_ += sm;
  }
  void OnModel(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    force_model_t m;
    if (!messages::DecodeAndValidate(rbuf, &m, nullptr)) return;
    if (m.epoch == excluded_epoch_.load()) return;
    if (m.epoch != status_filter_.epoch() || status_filter_.epoch() == 0) return;
    if (m.sender_role != static_cast<int8_t>(auth::Role::kServer) || m.sender_name != device_.name() ||
        !auth::VerifyMac(rbuf->data, rbuf->data_size, channel, *device_.mac_key())) {
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    ++genuine_models_;
  }

  messages::Channels channels_;
  const auth::KeySet device_;
  lcm::LCM lcm_{kUrl};
  auth::FreshnessFilter status_filter_{"status", auth::FreshnessFilter::EpochPolicy::kAdopt};
  std::atomic<bool> stop_{false};
  std::atomic<int64_t> excluded_epoch_{0};
  std::thread thread_;
  std::mutex mutex_;
  int64_t genuine_models_ = 0, statuses_ = 0;
  double max_gap_s_ = 0.0;
  Clock::time_point last_status_{};
  std::string seen_;
};

TEST(RogueTest, NoKeyNoForceNoCommandsAndTheGenuineSessionStillWorks) {
  const SessionKeyFile key_file;  // SNAPTHREAD_KEY_FILE for every genuine binary
  const ScopedTempDir tmp("rogue");
  const std::string dir = tmp.path();
  const std::string bin = BinDir();
  const std::string session = UniqueSession("ROGUE");
  const std::string scene = ScenePath("curve2d_snap.yaml");
  const std::string log = dir + "/genuine.lcmlog";
  auto server_argv = [&](const std::string& duration, const std::string& summary) {
    return std::vector<std::string>{bin + "/snapthread-server", "--scene", scene, "--session",
                                    session, "--lcm-url", kUrl, "--duration", duration,
                                    "--summary", summary, "--log-level", "warn"};
  };
  auto device_argv = [&](const std::string& duration, const std::string& summary) {
    return std::vector<std::string>{bin + "/snapthread-device", "--backend", "virtual-hand",
                                    "--scene", scene, "--session", session, "--lcm-url", kUrl,
                                    "--duration", duration, "--no-rt", "--summary", summary,
                                    "--log-level", "warn"};
  };

  // 1. A genuine session, logged; its epoch (what the rogue replays) noted.
  int64_t logged_epoch = 0;
  {
    Watcher recorded(session, key_file.key());
    ASSERT_TRUE(recorded.good());
    ChildProcess logger({SNAPTHREAD_LCM_LOGGER, "-q", "-c", session + "_.*",
                         std::string("--lcm-url=") + kUrl, "-f", log},
                        OneLog(dir + "/logger.txt"));
    ASSERT_TRUE(logger.started()) << SNAPTHREAD_LCM_LOGGER << " missing";
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    ChildProcess server(server_argv("10", dir + "/server0.json"), OneLog(dir + "/server0.txt"));
    ASSERT_TRUE(server.started());
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    ChildProcess device(device_argv("2", dir + "/device0.json"), OneLog(dir + "/device0.txt"));
    int code = -1;
    ASSERT_TRUE(device.Wait(20.0, &code));
    ASSERT_EQ(code, 0) << device.Out();
    server.Signal(SIGTERM);
    ASSERT_TRUE(server.Wait(5.0, &code));
    logger.Signal(SIGINT);
    logger.WaitOrKill(3.0);
    EXPECT_GT(JsonNumber(ReadFile(dir + "/device0.json"), "models_received"), 500)
        << "the recorded session must hold genuine models to replay";
    logged_epoch = recorded.epoch();
    ASSERT_NE(logged_epoch, 0) << "no authenticated status seen in the recorded session";
  }

  // 2. The rogue for the rest of the test; a lone device under it.
  ChildProcess rogue({bin + "/snapthread-rogue", kUrl, session, "14", log}, OneLog(dir + "/rogue.txt"));
  ASSERT_TRUE(rogue.started());
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  {
    ChildProcess device(device_argv("3", dir + "/device1.json"), OneLog(dir + "/device1.txt"));
    int code = -1;
    ASSERT_TRUE(device.Wait(20.0, &code));
    ASSERT_EQ(code, 0) << device.Out();
    const std::string summary = ReadFile(dir + "/device1.json");
    EXPECT_EQ(JsonNumber(summary, "models_received"), 0.0) << summary;
    EXPECT_LT(JsonNumber(summary, "max_force_n"), 0.05) << summary;
    EXPECT_GT(JsonNumber(summary, "models_rejected"), 1000.0) << summary;  // ~2 kHz forged
  }

  // 3. A lone server under the rogue: no forged pose answered, scene and method kept,
  // status flowing; 4. then a genuine device gets its models.
  Watcher watcher(session, key_file.key());
  ASSERT_TRUE(watcher.good());
  watcher.Exclude(logged_epoch);
  ChildProcess server(server_argv("9", dir + "/server.json"), OneLog(dir + "/server.txt"));
  ASSERT_TRUE(server.started());
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  watcher.Mark();
  std::this_thread::sleep_for(std::chrono::seconds(3));
  EXPECT_EQ(watcher.genuine_models(), 0) << "the lone server answered forged poses";
  EXPECT_LT(watcher.max_gap_s(), 0.5) << "status gap";
  EXPECT_GT(watcher.statuses(), 20);

  watcher.Mark();
  // 3 s of models plus the start-up (LCM, the first signed status at 10 Hz).
  ChildProcess device(device_argv("3.5", dir + "/device2.json"), OneLog(dir + "/device2.txt"));
  int code = -1;
  ASSERT_TRUE(device.Wait(20.0, &code));
  ASSERT_EQ(code, 0) << device.Out();
  EXPECT_LT(watcher.max_gap_s(), 0.5) << "status gap";
  server.Signal(SIGTERM);
  ASSERT_TRUE(server.Wait(5.0, &code));
  const std::string device_summary = ReadFile(dir + "/device2.json");
  // 1,500 in 3 s is the Release server's speed; a sanitized build divides it.
  EXPECT_GT(JsonNumber(device_summary, "models_received"), 1500.0 / SpeedScale())
      << device_summary << ReadFile(dir + "/server.json");
  const std::string server_summary = ReadFile(dir + "/server.json");
  EXPECT_GT(JsonNumber(server_summary, "rejected_messages"), 100.0) << server_summary;
  EXPECT_EQ(JsonNumber(server_summary, "commands_applied"), 0.0) << server_summary;
  // One scene and method throughout (the forged LOAD_SCENE / SET_METHOD never applied).
  EXPECT_EQ(watcher.scenes_and_methods(), "curve2d_snap/higher-order;") << ReadFile(dir + "/server.txt");
  rogue.WaitOrKill(15.0);
}

}  // namespace
}  // namespace snapthread
