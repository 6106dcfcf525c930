// A stranger without the key floods the device's channels before and while a session runs:
// forged solver statuses (well-formed, 12 kB of strings each, a made-up epoch and MAC),
// 1 MiB datagrams on the status channel, and forged force models. The device must still
// learn the genuine server's epoch from its statuses and feel its models: every unchecked
// status is checked before another datagram is read, so none is pushed out unchecked
// (statuses_superseded == 0), oversized ones are dropped unread, forged ones refused and
// counted. snapthread-device runs as a process against a fake server in this test (the
// one of tests/service/device_fake_server.h) over udpm on loopback.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "device_fake_server.h"
#include "messages/channels.h"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "test_support.h"

namespace snapthread::device {
namespace {

using testing::DeviceProcess;
using testing::FakeServer;
using testing::WriteDeviceScene;

// A multicast group and port of this test alone: the flood would otherwise fill the socket
// buffers of every other test's processes on the shared group (they would lose datagrams).
constexpr char kFloodUrl[] = "udpm://239.255.76.93:7693?ttl=0";

// The stranger: publishes forged statuses and models in batches as fast as it can (it
// yields 1 ms between batches so the machine's other tests keep a core), and one 1 MiB
// datagram on the status channel every 100 ms.
class Flooder {
 public:
  explicit Flooder(const std::string& session)
      : channels_(session), lcm_(kFloodUrl) {
    if (!lcm_.good()) return;
    thread_ = std::thread([this] { Run(); });
  }
  ~Flooder() { Stop(); }
  bool good() { return lcm_.good(); }
  void Stop() {
    stop_.store(true);
    if (thread_.joinable()) thread_.join();
  }
  uint64_t statuses() const { return statuses_.load(); }
  uint64_t models() const { return models_.load(); }
  uint64_t huge() const { return huge_.load(); }

 private:
  void Run() {
    std::mt19937_64 rng(23);
    solver_status_t st{};
    st.scene = std::string(4096, 's');
    st.method = std::string(4096, 'm');
    st.knot = std::string(4096, 'k');
    force_model_t m{};
    m.status = force_model_t::STATUS_REGULAR;
    m.f0[1] = 3.0;  // what a forged model would push with
    const std::vector<uint8_t> big(1 << 20, 0xEE);
    auto next_big = std::chrono::steady_clock::now();
    int64_t seq = 1000000000;
    while (!stop_.load()) {
      for (int i = 0; i < 40; ++i) {
        st.epoch = static_cast<int64_t>(rng());
        st.auth_seq = ++seq;
        for (auto& b : st.mac) b = static_cast<uint8_t>(rng());
        if (lcm_.publish(channels_.solver_status, &st) == 0) statuses_.fetch_add(1);
        m.epoch = st.epoch;
        m.auth_seq = seq;
        m.device_seq = static_cast<int64_t>(rng() % 100000);
        for (auto& b : m.mac) b = static_cast<uint8_t>(rng());
        if (lcm_.publish(channels_.force_model, &m) == 0) models_.fetch_add(1);
      }
      if (std::chrono::steady_clock::now() >= next_big) {
        if (lcm_.publish(channels_.solver_status, big.data(), static_cast<unsigned>(big.size())) == 0) {
          huge_.fetch_add(1);
        }
        next_big += std::chrono::milliseconds(100);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }

  messages::Channels channels_;
  lcm::LCM lcm_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> statuses_{0}, models_{0}, huge_{0};
};

TEST(DeviceFloodAttackTest, GenuineStatusesAndModelsGetThroughAFloodOfForgedOnes) {
  const test_support::SessionKeyFile key_file;  // SNAPTHREAD_KEY_FILE for the device
  const test_support::ScopedTempDir scoped("device_flood");
  const std::string& dir = scoped.path();
  const std::string session = test_support::UniqueSession("DEVFLOOD");

  // The flood is on before the device and the server start.
  Flooder flood(session);
  ASSERT_TRUE(flood.good()) << "udpm on loopback unavailable";
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const double duration_s = 4.0;
  const std::string scene = WriteDeviceScene(dir, "device_flood_test");
  const uint64_t flood_at_device_start = flood.statuses();
  DeviceProcess device({test_support::BinDir() + "/snapthread-device", "--backend", "sim-path",
                        "--scene", scene, "--session", session, "--lcm-url",
                        kFloodUrl, "--duration", std::to_string(duration_s),
                        "--speed-m-per-s", "0.04", "--no-rt", "--log-level", "warn",
                        "--summary", dir + "/summary.json"},
                       dir + "/device");
  ASSERT_TRUE(device.started());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const uint64_t flood_statuses_0 = flood.statuses(), flood_models_0 = flood.models();
  const auto t0 = std::chrono::steady_clock::now();
  FakeServer server(session, &key_file.key(), kFloodUrl);
  ASSERT_TRUE(server.good());
  const int code = device.ExitCode(30.0 * test_support::SpeedScale());
  const double flood_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const int genuine_statuses = server.statuses_sent();
  server.Stop();
  const double status_rate = (flood.statuses() - flood_statuses_0) / flood_s;
  const double forged_during_device = static_cast<double>(flood.statuses() - flood_at_device_start);
  const double model_rate = (flood.models() - flood_models_0) / flood_s;
  flood.Stop();
  ASSERT_EQ(code, 0) << test_support::ReadFile(dir + "/device.err");

  const auto s = test_support::ReadJsonNumbers(dir + "/summary.json");
  ASSERT_FALSE(s.empty()) << test_support::ReadFile(dir + "/device.err");
  std::printf("flood: %.0f forged statuses/s (12 kB), %.0f forged models/s, %llu datagrams of 1 MiB; "
              "genuine statuses sent %d, accepted %.0f; status refusals %.0f, superseded %.0f, "
              "oversized %.0f; models received %.0f, rejected %.0f; max |F| %.3f N\n",
              status_rate, model_rate, static_cast<unsigned long long>(flood.huge()),
              genuine_statuses, s.at("statuses_accepted"), s.at("statuses_rejected"),
              s.at("statuses_superseded"), s.at("statuses_oversized"), s.at("models_received"),
              s.at("models_rejected"), s.at("max_force_n"));

  // It was a flood: far more forged statuses than genuine ones (20/s), and they arrived.
  // Rates and counts that depend on the build's speed are divided by SpeedScale.
  const double scale = test_support::SpeedScale();
  EXPECT_GT(status_rate, 50.0 * 20.0 / scale);
  EXPECT_GT(s.at("statuses_rejected"), 1000.0 / scale);
  EXPECT_GT(s.at("statuses_oversized"), 0.0);
  EXPECT_GT(s.at("models_rejected"), 1000.0 / scale);
  // Nothing the device read was pushed out unchecked. What it could not read (the kernel's
  // socket buffer overflows when the machine is busy) it loses whatever it is, so the
  // genuine statuses must get through at least half as well as the forged ones did
  // (statuses checked / sent): a flood cannot single them out.
  EXPECT_EQ(s.at("statuses_superseded"), 0.0);
  const double forged_checked = s.at("statuses_rejected") / forged_during_device;
  const double genuine_heard = s.at("statuses_accepted") / genuine_statuses;
  std::printf("statuses checked while the device ran: forged %.2f, genuine %.2f\n", forged_checked,
              genuine_heard);
  EXPECT_GE(genuine_heard, 0.5 * std::min(1.0, forged_checked));
  EXPECT_GE(s.at("statuses_accepted"), 3.0);
  // The genuine models were felt: the server ran ~3.5 s of the device's 4 s at ~1 model
  // per pose (1 kHz); at least a tenth of that (a busy machine loses many to the kernel
  // under the flood), and the spring's force (a few N at most).
  EXPECT_GT(s.at("models_received"), 350.0 / scale);
  EXPECT_GT(s.at("max_force_n"), 0.05);
  EXPECT_EQ(s.at("nonfinite_outputs"), 0.0);
}

}  // namespace
}  // namespace snapthread::device
