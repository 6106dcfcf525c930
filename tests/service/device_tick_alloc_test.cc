// Proves the servo tick (read device -> latest model -> safety -> command -> rings)
// never allocates: the heap allocations of the servo thread are counted
// (tests/support/allocation_counter.h, after Drake's iiwa_command_sender_test.cc malloc
// guard), one warm-up tick runs, then 10,000 ticks must allocate nothing, through fresh
// models, stale-model fades, out-of-workspace poses, full rings and both simulated
// backends, a snap-ahead crossing of a fold reached by turning; and the same through
// DeviceClient::Tick (the production path) with its receive and io steps run between
// the ticks.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "allocation_counter.h"
#include "device_client.h"
#include "device_fakes.h"
#include "safety.h"
#include "realtime/percentiles.h"
#include "servo_loop.h"
#include "sim_path_device.h"
#include "virtual_hand_device.h"

namespace snapthread::device {
namespace {

int64_t g_now_us = 0;
int64_t TestClock() { return g_now_us; }

using test_support::AllocationCounter;

TEST(DeviceMallocGuardTest, GuardCountsAllocations) {
  // The counter must be able to fail: an allocation inside it is seen.
  long n = 0;
  {
    AllocationCounter counter;
    auto v = std::make_unique<std::vector<double>>(100);
    n = counter.mallocs();
  }
  EXPECT_GE(n, 2);
}

force_model_t SpringModel(int64_t seq) {
  force_model_t m{};
  m.seq = seq;
  m.device_seq = seq;
  m.status = seq % 50 == 0 ? force_model_t::STATUS_SNAPPED : force_model_t::STATUS_REGULAR;
  m.f0[0] = 0.5;
  m.f0[1] = 0.1 * static_cast<double>(seq % 7);
  for (int i = 0; i < 3; ++i) m.K[i][i] = -400.0;
  m.K[0][1] = m.K[1][0] = 30.0;
  return m;
}

// The same with a 6-DoF wrench (a rod's grasp): torque, q0 and K6.
force_model_t WrenchModel(int64_t seq) {
  force_model_t m = SpringModel(seq);
  m.has_torque = 1;
  m.has_wrench = 1;
  m.torque0[0] = 0.001 * static_cast<double>(seq % 90);
  m.q0[0] = std::sqrt(0.5);
  m.q0[1] = std::sqrt(0.5);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m.K6[i][j] = m.K[i][j];
    m.K6[3 + i][3 + i] = -0.02;
  }
  m.K6[1][5] = m.K6[5][1] = 0.01;
  return m;
}

// The same with a fold reached by turning about z (snap-ahead, issue 17 item 5): the
// boundary in the pose chart, at 1.5 rad, a new fold id every 200 models; device_seq
// outruns the poses' seq so a switch ends at the next model and the check runs again.
force_model_t TurningFoldModel(int64_t seq) {
  force_model_t m = WrenchModel(seq);
  m.device_seq = 10 * seq;
  m.has_fold = 1;
  m.fold_id = 1 + seq / 200;
  m.fold_normal_r[2] = 1.0;
  m.fold_q[0] = std::cos(0.75);
  m.fold_q[3] = std::sin(0.75);
  m.post_f0[1] = -0.5;
  m.post_torque0[2] = 0.01;
  for (int i = 0; i < 3; ++i) m.post_K[i][i] = -200.0;
  return m;
}

// Runs the ticks; returns the number of rejected poses. With `snap_ahead` the tick
// selects through it (and the models carry a turning fold).
uint64_t RunTicks(HapticDevice* device, int ticks, bool wrench = false, SnapAhead* snap_ahead = nullptr) {
  EXPECT_TRUE(device->Open(nullptr));
  SafetyLimits limits;
  limits.workspace_radius_m = 0.05;
  ForceSafety safety(limits, device->capabilities().has_orientation, device->capabilities().has_torque_output);
  auto models = std::make_unique<ModelSlot>();
  auto poses = std::make_unique<PoseRing>();
  auto trace = std::make_unique<TraceRing>();
  auto lateness = std::make_unique<LatenessRing>();
  ServoTickOptions options;
  options.publish_divisor = 2;
  ServoTick tick(device, &safety, models.get(), poses.get(), trace.get(), lateness.get(), options);
  if (snap_ahead != nullptr) tick.SetSnapAhead(snap_ahead);

  // Warm-up tick (first use of everything).
  g_now_us += 1000;
  tick.Tick(g_now_us, 5);

  int64_t seq = 0;
  long allocations = 0;
  for (int i = 0; i < ticks; ++i) {
    // Off-RT work, not counted: the LCM thread's model hand-over (with 300 ms silences
    // to exercise the fade) and the io thread's draining (stopped for a while so the
    // rings fill up).
    const bool silent = (i / 1000) % 3 == 2 && (i % 1000) < 300;
    if (i % 5 == 0 && !silent) {
      LocalModel m;
      ++seq;
      const force_model_t msg = snap_ahead != nullptr ? TurningFoldModel(seq)
                                : wrench              ? WrenchModel(seq)
                                                      : SpringModel(seq);
      EXPECT_NE(PrepareModel(msg, g_now_us, limits, &m, nullptr), ModelVerdict::kRejected);
      models->Write(m);
    }
    if (i % 100 == 0 && i < 1000) {
      PoseToPublish p;
      TraceRow r;
      int32_t l;
      while (poses->TryPop(&p)) {}
      while (trace->TryPop(&r)) {}
      while (lateness->TryPop(&l)) {}
    }
    g_now_us += 1000;
    AllocationCounter counter;
    tick.Tick(g_now_us, i % 37);
    allocations += counter.mallocs();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(tick.counters().ticks.load(), static_cast<uint64_t>(ticks) + 1);
  // The run went through the paths it claims to cover.
  EXPECT_GT(safety.counters().fade_ticks.load(), 0u);
  EXPECT_GT(trace->dropped(), 0u);  // rings filled up once draining stopped
  EXPECT_EQ(safety.counters().nonfinite_outputs.load(), 0u);
  device->Close();
  return safety.counters().poses_rejected.load();
}

TEST(DeviceServoTickAllocationTest, VirtualHandTickNeverAllocates) {
  VirtualHandDevice hand(ScriptedPath({{-0.02, 0.0, 0.0}, {0.02, 0.01, 0.0}}, 0.05), {},
                         &TestClock);
  EXPECT_EQ(RunTicks(&hand, 10000), 0u);
}

TEST(DeviceServoTickAllocationTest, SimPathTickNeverAllocatesIncludingOutOfWorkspace) {
  // The path leaves the 5 cm workspace: poses are rejected (zero force, not published).
  SimPathDevice sim(ScriptedPath({{-0.04, 0.0, 0.0}, {0.08, 0.0, 0.0}}, 0.05), &TestClock);
  EXPECT_GT(RunTicks(&sim, 10000), 1000u);
}

// A rolling hand (a rod scene's path) with 6-DoF models and the torque rendered.
TEST(DeviceServoTickAllocationTest, SimPathWrenchTickNeverAllocates) {
  SimPathDevice sim(ScriptedPath({{-0.02, 0.0, 0.0}, {0.02, 0.0, 0.0}}, {{0.0, 0.0, 0.0}, {9.0, 0.5, 0.0}},
                                 0.05, 3.0),
                    &TestClock);
  RunTicks(&sim, 10000, true);
}

// Snap-ahead's crossing check from the hand's quaternion (a fold reached by turning):
// the hand turns back and forth through the fold, the tick switches to post-snap models.
TEST(DeviceServoTickAllocationTest, TurningFoldCrossingNeverAllocates) {
  SimPathDevice sim(ScriptedPath({{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}, {{0.0, 0.0, 0.0}, {0.0, 0.0, 3.0}}, 0.05, 3.0),
                    &TestClock);
  SnapAhead snap_ahead;
  RunTicks(&sim, 10000, true, &snap_ahead);
  EXPECT_GE(snap_ahead.switches(), 3u) << "the hand crossed the fold and the tick switched";
}

TEST(DeviceServoTickAllocationTest, DeviceClientTickNeverAllocates) {
  g_now_us += 1000000;
  VirtualHandDevice hand(ScriptedPath({{-0.02, 0.0, 0.0}, {0.02, 0.01, 0.0}}, 0.05), {},
                         &TestClock);
  ASSERT_TRUE(hand.Open(nullptr));
  testing::InMemoryTransport transport;
  testing::SpringServer server(&transport, 300.0);
  DeviceClientConfig config;
  config.loop.realtime = false;
  config.log_period_us = 0;
  config.clock = &TestClock;
  DeviceClient client(&hand, &transport, config);
  g_now_us += 1000;
  client.Tick(g_now_us, 3);  // warm-up
  long allocations = 0;
  for (int i = 0; i < 10000; ++i) {
    // Off the servo thread, not counted: the io step publishes poses, the fake server
    // answers (silent for 300 ms every 3 s, to exercise the fade), the receive step
    // decodes and hands the models over.
    client.Service(g_now_us);
    if ((i / 1000) % 3 == 2 && (i % 1000) < 300) {
      server.TakeNewPoses();
    } else {
      server.AnswerAll();
    }
    client.Receive(0);
    g_now_us += 1000;
    AllocationCounter counter;
    client.Tick(g_now_us, i % 37);
    allocations += counter.mallocs();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_GT(client.receiver().received(), 5000u);
  EXPECT_GT(client.safety().counters().fade_ticks.load(), 0u);
  EXPECT_EQ(client.safety().counters().nonfinite_outputs.load(), 0u);
  hand.Close();
}

TEST(DeviceMallocGuardTest, SampleWindowPushAndComputeNeverAllocate) {
  realtime::SampleWindow window(1000);
  window.Compute();  // warm-up
  long allocations = 0;
  {
    AllocationCounter counter;
    for (int i = 0; i < 10000; ++i) window.Push(static_cast<double>(i % 977));
    const auto s = window.Compute();
    allocations = counter.mallocs();
    EXPECT_EQ(s.count, 1000u);
    EXPECT_EQ(s.max, 976.0);
  }
  EXPECT_EQ(allocations, 0);
}

}  // namespace
}  // namespace snapthread::device
