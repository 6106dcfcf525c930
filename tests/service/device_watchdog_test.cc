// The servo-level watchdog: StaleCommand (a backend renders zero once the last command is
// older than 5 ms) and the simulated backends' render thread (SimRenderer, their
// "firmware"), which renders apart from the servo loop. Stopping a real ServoLoop thread
// while the render thread runs must bring the rendered force to zero within 10 ms of the
// last command (measured on the render thread's own clock, repeated; median printed).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <thread>
#include <vector>

#include "realtime/clock.h"
#include "safety.h"
#include "scripted_path.h"
#include "servo_loop.h"
#include "sim_path_device.h"
#include "sim_renderer.h"
#include "stale_command.h"
#include "test_support.h"
#include "virtual_hand_device.h"

namespace snapthread::device {
namespace {

int64_t g_now_us = 0;
int64_t FakeClock() { return g_now_us; }

TEST(StaleCommandTest, RendersTheCommandWhileFreshThenZero) {
  StaleCommand c(5000);
  double f[3], t[3];
  EXPECT_FALSE(c.Output(1000, f, t));  // nothing commanded yet
  EXPECT_EQ(f[0], 0.0);
  const double force[3] = {1.0, -2.0, 3.0}, torque[3] = {0.1, 0.2, 0.3};
  c.Set(force, torque, 10000);
  EXPECT_TRUE(c.Output(10000, f, t));
  EXPECT_TRUE(c.Output(15000, f, t));  // exactly the limit: still fresh
  EXPECT_EQ(f[1], -2.0);
  EXPECT_EQ(t[2], 0.3);
  EXPECT_TRUE(c.Output(9990, f, t));  // stamped by a clock read a moment later
  EXPECT_EQ(c.stale_outputs(), 0u);
  EXPECT_FALSE(c.Output(15001, f, t));
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(f[k], 0.0);
    EXPECT_EQ(t[k], 0.0);
  }
  EXPECT_EQ(c.stale_outputs(), 1u);
  EXPECT_EQ(c.last_command_us(), 10000);
  c.Set(force, nullptr, 20000);  // no torque output: zero torque
  EXPECT_TRUE(c.Output(20001, f, t));
  EXPECT_EQ(f[0], 1.0);
  EXPECT_EQ(t[0], 0.0);
  c.Clear(20002);
  EXPECT_TRUE(c.Output(20003, f, t));
  EXPECT_EQ(f[0], 0.0);
}

// One writer at full speed, two readers: a reader sees a whole command or zero, never a
// mix of two (every command has all six components equal to its stamp).
TEST(StaleCommandTest, ReadersNeverSeeATornCommand) {
  StaleCommand c(1000000000);
  std::atomic<bool> stop{false};
  std::atomic<uint64_t> torn{0}, reads{0};
  auto reader = [&] {
    double f[3], t[3];
    while (!stop.load()) {
      if (!c.Output(INT64_MAX / 4, f, t)) continue;
      reads.fetch_add(1);
      for (int k = 0; k < 3; ++k) {
        if (f[k] != f[0] || t[k] != f[0]) torn.fetch_add(1);
      }
    }
  };
  std::thread r1(reader), r2(reader);
  for (int64_t i = 1; i <= 2000000 && (i < 20000 || reads.load() < 1000); ++i) {
    const double v = static_cast<double>(i);
    const double w[3] = {v, v, v};
    c.Set(w, w, INT64_MAX / 4 - 1);
  }
  stop.store(true);
  r1.join();
  r2.join();
  EXPECT_EQ(torn.load(), 0u);
  EXPECT_GT(reads.load(), 0u);
}

// A virtual hand whose servo stalls for 40 ms after commanding 1 N: the hand is pushed
// for the command's 5 ms only, not for the whole stall.
TEST(StaleCommandTest, VirtualHandIsNotPushedByAStaleCommand) {
  auto displacement_after_stall = [](bool keep_commanding) {
    g_now_us = 0;
    VirtualHandDevice hand(ScriptedPath({{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}, 0.01), {},
                           &FakeClock);
    EXPECT_TRUE(hand.Open(nullptr));
    DeviceState st;
    const double push[3] = {0.0, 1.0, 0.0}, zero[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i < 100; ++i) {  // at rest on the path
      g_now_us += 1000;
      hand.Read(&st);
      hand.Command(zero, zero);
    }
    hand.Command(push, zero);
    // The stall: no Read, no Command (or, for comparison, commands every millisecond).
    for (int i = 0; i < 40; ++i) {
      g_now_us += 1000;
      if (keep_commanding) {
        hand.Read(&st);
        hand.Command(push, zero);
      }
    }
    hand.Read(&st);
    return std::make_pair(st.position_m[1], hand.command().stale_outputs());
  };
  const auto [stalled, stale_outputs] = displacement_after_stall(false);
  const auto [pushed, fresh_stale] = displacement_after_stall(true);
  EXPECT_GT(stale_outputs, 0u);
  EXPECT_EQ(fresh_stale, 0u);
  EXPECT_GT(stalled, 0.0);  // the first 5 ms did push it
  // 1 N for 40 ms moves the 0.1 kg hand ~3 mm against its spring; 5 ms of it far less.
  EXPECT_GT(pushed, 1e-3);
  EXPECT_LT(stalled, 0.25 * pushed) << "stalled " << stalled << " m, pushed " << pushed << " m";
}

TEST(SimRendererTest, RecordsWhenTheOutputTurnedZero) {
  g_now_us = 1000000;
  SimPathDevice device(ScriptedPath({{0.0, 0.0, 0.0}, {0.01, 0.0, 0.0}}, 0.01), &FakeClock);
  ASSERT_TRUE(device.Open(nullptr));
  SimRenderer renderer(&device.command(), &FakeClock);
  const double f[3] = {0.5, 0.0, 0.0}, t[3] = {0.0, 0.0, 0.01};
  device.Command(f, t);
  RenderedSample s;
  for (int i = 0; i < 12; ++i) {
    renderer.RenderOnce(g_now_us);
    ASSERT_TRUE(ReadRendered(renderer.record(), &s));
    if (i <= 5) {
      EXPECT_EQ(s.force_n[0], 0.5) << i;
      EXPECT_EQ(s.torque_nm[2], 0.01) << i;
      EXPECT_EQ(s.zero_since_us, INT64_MIN) << i;
    } else {
      EXPECT_TRUE(s.IsZero()) << i;
      EXPECT_EQ(s.zero_since_us, 1006000) << i;  // the first render past the 5 ms limit
    }
    g_now_us += 1000;
  }
  EXPECT_EQ(s.command_us, 1000000);
  EXPECT_EQ(s.renders, 12u);
  device.Command(f, t);  // a new command: rendered again
  renderer.RenderOnce(g_now_us);
  ASSERT_TRUE(ReadRendered(renderer.record(), &s));
  EXPECT_EQ(s.force_n[0], 0.5);
  EXPECT_EQ(s.zero_since_us, INT64_MIN);
}

// A real servo loop (its own thread, CLOCK_MONOTONIC) commands a sim-path device whose
// render thread runs apart; a feeder thread keeps a 1 N model fresh, as the receive thread
// would. Then the servo loop is stopped: the render thread's output must be zero within
// 10 ms of the last command, and stay zero.
TEST(DeviceWatchdogTest, StoppedServoLoopZeroesTheRenderedForceWithin10Ms) {
  SimPathDevice device(ScriptedPath({{0.0, 0.0, 0.0}, {0.01, 0.0, 0.0}}, 0.01),
                       &realtime::MonotonicMicros);
  ASSERT_TRUE(device.Open(nullptr));
  std::string error;
  ASSERT_TRUE(device.renderer().Start("", &error)) << error;
  SafetyLimits limits;
  limits.fade_time_s = 0.02;
  ForceSafety safety(limits, true, true);
  ModelSlot models;
  ServoTick tick(&device, &safety, &models, nullptr, nullptr, nullptr, {});
  ServoLoopOptions loop_options;
  loop_options.realtime = false;  // no mlockall in a test process
  ServoLoop loop(&tick, loop_options);

  std::atomic<bool> stop_feeder{false};
  std::thread feeder([&] {
    while (!stop_feeder.load()) {
      LocalModel m;
      m.status = force_model_t::STATUS_REGULAR;
      m.f0_n[1] = 1.0;
      m.receive_us = realtime::MonotonicMicros();
      models.Write(m);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  });

  std::vector<double> latencies_ms;
  for (int round = 0; round < 10; ++round) {
    loop.Start(nullptr);
    RenderedSample s;
    // Pushing: the render thread renders the servo's (faded-in) 1 N.
    ASSERT_TRUE(test_support::WaitUntil(
        [&] { return ReadRendered(device.renderer().record(), &s) && s.force_n[1] > 0.5; }, 5.0,
        0.001))
        << "round " << round << ": the rendered force never reached 0.5 N";
    loop.Stop();
    const int64_t last_command_us = device.command().last_command_us();
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    ASSERT_TRUE(ReadRendered(device.renderer().record(), &s));
    const uint64_t renders = s.renders;
    EXPECT_TRUE(s.IsZero()) << "round " << round << ": still rendering " << s.force_n[1] << " N";
    EXPECT_EQ(s.command_us, last_command_us);
    ASSERT_NE(s.zero_since_us, INT64_MIN);
    const double latency_ms = 1e-3 * static_cast<double>(s.zero_since_us - last_command_us);
    latencies_ms.push_back(latency_ms);
    // Zero from within 10 ms of the last command; the limit itself (5 ms) was respected.
    EXPECT_LE(latency_ms, 10.0) << "round " << round;
    EXPECT_GT(latency_ms, 5.0) << "round " << round;
    // The render thread keeps rendering (zero) while the servo is stopped.
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_TRUE(ReadRendered(device.renderer().record(), &s));
    EXPECT_GT(s.renders, renders);
    EXPECT_TRUE(s.IsZero());
  }
  stop_feeder.store(true);
  feeder.join();
  std::sort(latencies_ms.begin(), latencies_ms.end());
  std::printf("rendered force zero after the last command: median %.2f ms, max %.2f ms (%zu stops)\n",
              latencies_ms[latencies_ms.size() / 2], latencies_ms.back(), latencies_ms.size());
  EXPECT_GT(device.command().stale_outputs(), 0u);
}

}  // namespace
}  // namespace snapthread::device
