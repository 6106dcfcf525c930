// DeviceClient without LCM: 1000 servo ticks against an in-memory transport and a fake
// server that answers every pose with the force model of a known linear spring
// (device_fakes.h). One thread drives the client's three steps (Tick, Service, Receive)
// on a fake clock, so every assertion is exact and repeatable.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "device_client.h"
#include "device_fakes.h"
#include "sim_path_device.h"

namespace snapthread::device {
namespace {

using testing::InMemoryTransport;
using testing::SpringServer;

int64_t g_now_us = 0;
int64_t FakeClock() { return g_now_us; }

double Norm(const double v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

std::vector<uint8_t> Encode(const force_model_t& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// Phases of the run, in ticks (1 ms each).
constexpr int kStiffFrom = 300;    // the server's spring becomes too stiff: clamps
constexpr int kBadFrom = 400;      // only rejected packets: the model goes stale, fades
constexpr int kInvalidFrom = 550;  // STATUS_INVALID models: zero force
constexpr int kSpringFrom = 600;   // the soft spring again
constexpr int kTicks = 1000;

TEST(DeviceClientTest, ThousandTicksAgainstAnInMemorySpringServer) {
  g_now_us = 1000000;
  SimPathDevice device(ScriptedPath({{-0.01, 0.0, 0.0}, {0.01, 0.005, 0.0}}, 0.02), &FakeClock);
  ASSERT_TRUE(device.Open(nullptr));
  InMemoryTransport transport;
  const double k_soft = 200.0, k_stiff = 5000.0;
  SpringServer server(&transport, k_soft);

  DeviceClientConfig config;
  config.device_id = "sim-path";
  config.limits = SafetyLimits{};  // 3 N, 800 N/m, 1000 N/s, 50 ms timeout, 100 ms fade
  config.loop.realtime = false;
  config.log_period_us = 0;
  config.clock = &FakeClock;
  DeviceClient client(&device, &transport, config);
  const SafetyLimits& limits = client.safety().limits();

  int bad_sent = 0, invalid_sent = 0, followed = 0;
  int64_t last_valid_receive_us = -1;
  double force_at_bad_start = 0.0, force_at_bad_end = 0.0;
  for (int i = 0; i < kTicks; ++i) {
    g_now_us += 1000;
    client.Tick(g_now_us, 0);
    const SafetyOutput& out = client.servo().last_output();
    const double* p = client.servo().last_state().position_m;
    const double f = Norm(out.force_n);
    ASSERT_TRUE(std::isfinite(f)) << i;
    EXPECT_LE(f, limits.max_force_n + 1e-12) << i;

    // Forces follow the model: once faded in, F(p) = -k p exactly (the model is exact).
    const bool soft = i < kStiffFrom || i >= kSpringFrom;
    const bool settled = (i >= 150 && i < kStiffFrom) || i >= kSpringFrom + 150;
    if (soft && settled) {
      for (int a = 0; a < 3; ++a) EXPECT_NEAR(out.force_n[a], -k_soft * p[a], 1e-9) << i;
      ++followed;
    }
    // The stiff spring asks for ~20 N at these poses: |F| is clamped to the limit.
    if (i >= kStiffFrom + 20 && i < kBadFrom) {
      EXPECT_TRUE(out.clamped) << i;
      EXPECT_NEAR(f, limits.max_force_n, 1e-9) << i;
    }
    // Rejected packets are never rendered: the servo keeps the last valid model.
    if (i >= kBadFrom && i < kInvalidFrom) {
      EXPECT_EQ(client.servo().counters().last_model_receive_us.load(), last_valid_receive_us) << i;
      if (i == kBadFrom) force_at_bad_start = f;
      if (i == kInvalidFrom - 1) force_at_bad_end = f;
    }
    if (i >= kInvalidFrom + 10 && i < kSpringFrom) {
      EXPECT_EQ(f, 0.0) << i;
    }

    client.Service(g_now_us);  // publishes the pose of this tick
    server.set_stiffness(i >= kStiffFrom && i < kBadFrom ? k_stiff : k_soft);
    if (i >= kBadFrom && i < kInvalidFrom) {
      // Garbage, a NaN stiffness, an unknown status, a truncated model: all refused.
      for (const auto& s : server.TakeNewPoses()) {
        force_model_t m = server.ModelFor(s);
        std::vector<uint8_t> bytes;
        switch (bad_sent % 4) {
          case 0: bytes.assign(40, 0xAB); break;
          case 1: m.K[1][1] = std::numeric_limits<double>::quiet_NaN(); bytes = Encode(m); break;
          case 2: m.status = 7; bytes = Encode(m); break;
          default: bytes = Encode(m); bytes.resize(bytes.size() - 9); break;
        }
        transport.Deliver(std::move(bytes));
        ++bad_sent;
      }
    } else if (i >= kInvalidFrom && i < kSpringFrom) {
      for (const auto& s : server.TakeNewPoses()) {
        force_model_t m = server.ModelFor(s);
        m.status = force_model_t::STATUS_INVALID;
        transport.Deliver(m);
        ++invalid_sent;
      }
    } else {
      server.AnswerAll();
    }
    const int got = client.Receive(0);
    if (got > 0 && !(i >= kBadFrom && i < kInvalidFrom)) last_valid_receive_us = g_now_us;
  }

  const ModelReceiver& rx = client.receiver();
  const DeviceClientSummary s = client.Summary(g_now_us);
  EXPECT_EQ(followed, (kStiffFrom - 150) + (kTicks - kSpringFrom - 150));
  // Every pose was published, in order, and every valid answer was taken.
  ASSERT_EQ(transport.states.size(), static_cast<size_t>(kTicks));
  for (int i = 0; i < kTicks; ++i) EXPECT_EQ(transport.states[i].seq, i);
  EXPECT_EQ(bad_sent, kInvalidFrom - kBadFrom);
  EXPECT_EQ(invalid_sent, kSpringFrom - kInvalidFrom);
  EXPECT_EQ(rx.rejected(), static_cast<uint64_t>(bad_sent));
  EXPECT_EQ(rx.invalid_models(), static_cast<uint64_t>(invalid_sent));
  EXPECT_EQ(rx.received(), static_cast<uint64_t>(kTicks - bad_sent));
  // Clamps: every stiff model's K was clamped, and |F| was.
  EXPECT_EQ(rx.stiffness_clamps(), static_cast<uint64_t>(kBadFrom - kStiffFrom));
  EXPECT_GT(s.force_clamps, 50u);
  // The stale model faded: fade ticks counted, the force went to zero.
  EXPECT_GT(s.fade_ticks, 50u);
  EXPECT_GT(force_at_bad_start, 2.0);
  EXPECT_LT(force_at_bad_end, 0.05);
  EXPECT_EQ(s.nonfinite_outputs, 0u);
  // The server echoed each pose: round trips were measured (0 on the one fake clock).
  EXPECT_EQ(s.round_trip_us.count, rx.received());
  // DEVICE_STATUS at 2 Hz over 1 s of fake time, with the counters of the moment.
  ASSERT_EQ(transport.statuses.size(), 2u);
  EXPECT_EQ(transport.statuses.back().models_rejected, bad_sent);
  EXPECT_EQ(transport.statuses.back().ticks, kTicks);
  EXPECT_EQ(transport.statuses.back().device_id, "sim-path");
}

TEST(DeviceClientTest, UnwritableTraceIsAStartUpError) {
  SimPathDevice device(ScriptedPath({{0.0, 0.0, 0.0}}, 0.02), &FakeClock);
  InMemoryTransport transport;
  DeviceClientConfig config;
  config.trace_file = "/nonexistent-dir/trace.csv";
  config.clock = &FakeClock;
  EXPECT_THROW(DeviceClient(&device, &transport, config), std::runtime_error);
}

}  // namespace
}  // namespace snapthread::device
