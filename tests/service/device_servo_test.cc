// ServoTick and ServoLoop: what the tick hands to the other threads (published poses,
// trace rows, lateness), and that the loop keeps its rate on a shared machine.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>
#include <thread>

#include "safety.h"
#include "scripted_path.h"
#include "servo_loop.h"
#include "sim_path_device.h"
#include "realtime/clock.h"

namespace snapthread::device {
namespace {

int64_t g_clock_us = 0;
int64_t Clock() { return g_clock_us; }

struct Rig {
  explicit Rig(ScriptedPath path, int publish_divisor, double workspace_m = 0.08)
      : device(std::move(path), &Clock) {
    EXPECT_TRUE(device.Open(nullptr));
    SafetyLimits limits;
    limits.workspace_radius_m = workspace_m;
    safety = std::make_unique<ForceSafety>(limits, false);
    ServoTickOptions o;
    o.publish_divisor = publish_divisor;
    tick = std::make_unique<ServoTick>(&device, safety.get(), &models, poses.get(), trace.get(),
                                       lateness.get(), o);
  }
  SimPathDevice device;
  std::unique_ptr<ForceSafety> safety;
  ModelSlot models;
  std::unique_ptr<PoseRing> poses = std::make_unique<PoseRing>();
  std::unique_ptr<TraceRing> trace = std::make_unique<TraceRing>();
  std::unique_ptr<LatenessRing> lateness = std::make_unique<LatenessRing>();
  std::unique_ptr<ServoTick> tick;
};

TEST(DeviceServoTickTest, PublishesEveryKthPoseWithConsecutiveSeq) {
  g_clock_us = 1000000;
  Rig rig(ScriptedPath({{0, 0, 0}, {0.02, 0, 0}}, 0.02), 4);
  for (int i = 0; i < 400; ++i) {
    g_clock_us += 1000;
    rig.tick->Tick(g_clock_us, 3);
  }
  PoseToPublish p;
  int n = 0;
  int64_t expected_seq = 0;
  while (rig.poses->TryPop(&p)) {
    EXPECT_EQ(p.seq, expected_seq++);
    EXPECT_EQ(p.buttons, 1);
    ++n;
  }
  EXPECT_EQ(n, 100);
  TraceRow r;
  int rows = 0;
  while (rig.trace->TryPop(&r)) {
    EXPECT_EQ(r.tick, rows);
    EXPECT_EQ(r.model_age_ms, -1.0);  // no model yet
    EXPECT_EQ(r.force_n[0], 0.0);
    ++rows;
  }
  EXPECT_EQ(rows, 400);
  int32_t l;
  int lat = 0;
  while (rig.lateness->TryPop(&l)) {
    EXPECT_EQ(l, 3);
    ++lat;
  }
  EXPECT_EQ(lat, 400);
}

TEST(DeviceServoTickTest, OutOfWorkspacePosesAreNeverPublished) {
  g_clock_us = 0;
  // From 0 to 10 cm and back with a 5 cm workspace: about half the poses are outside.
  Rig rig(ScriptedPath({{0, 0, 0}, {0.10, 0, 0}}, 0.1), 1, 0.05);
  LocalModel m;
  force_model_t msg{};
  msg.status = force_model_t::STATUS_REGULAR;
  msg.f0[1] = 1.0;
  for (int i = 0; i < 2000; ++i) {
    g_clock_us += 1000;
    PrepareModel(msg, g_clock_us, rig.safety->limits(), &m, nullptr);
    rig.models.Write(m);
    rig.tick->Tick(g_clock_us, 0);
    if (rig.tick->last_output().pose_rejected) {
      EXPECT_EQ(rig.tick->last_output().force_n[1], 0.0);
    }
  }
  PoseToPublish p;
  int published = 0;
  while (rig.poses->TryPop(&p)) {
    EXPECT_LE(std::abs(p.position_m[0]), 0.05 + 1e-12);
    ++published;
  }
  const auto rejected = rig.safety->counters().poses_rejected.load();
  EXPECT_GT(rejected, 800u);
  EXPECT_EQ(published + rejected, 2000u);
}

TEST(DeviceServoLoopTest, KeepsItsRateWithoutRealtime) {
  g_clock_us = 0;
  Rig rig(ScriptedPath({{0, 0, 0}}, 0.02), 1);
  ServoLoopOptions o;
  o.rate_hz = 1000.0;
  o.realtime = false;
  ServoLoop loop(rig.tick.get(), o);
  std::string notes;
  const auto t0 = std::chrono::steady_clock::now();
  loop.Start(&notes);
  EXPECT_TRUE(notes.empty()) << notes;
  EXPECT_FALSE(loop.realtime_active());
  // 600 ms fits in the rings (8192 lateness samples), so nothing needs draining.
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  loop.Stop();
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double ticks = static_cast<double>(rig.tick->counters().ticks.load());
  // Absolute deadlines: never faster than the rate; on a shared machine occasionally
  // slower (stalls re-anchor the schedule), so only a generous lower bound.
  EXPECT_LE(ticks, 1000.0 * elapsed_s + 5);
  EXPECT_GE(ticks, 0.25 * 1000.0 * 0.6);
  int32_t l;
  int n = 0, late_over_5ms = 0;
  while (rig.lateness->TryPop(&l)) {
    ++n;
    EXPECT_GE(l, 0);
    if (l > 5000) ++late_over_5ms;
  }
  EXPECT_EQ(n, static_cast<int>(ticks));
  EXPECT_LT(late_over_5ms, n / 4);  // the bulk of the wake-ups are on time
}

TEST(DeviceScriptedPathTest, CsvPathWithHeaderAndTwoColumns) {
  const std::string path = ::testing::TempDir() + "/device_path_test.csv";
  {
    std::ofstream f(path);
    f << "x_m,y_m\n# comment\n0,0\n0.01,0.02\n";
  }
  const ScriptedPath p = ScriptedPath::FromCsv(path, 0.01);
  ASSERT_EQ(p.waypoints_m().size(), 2u);
  EXPECT_EQ(p.waypoints_m()[1][1], 0.02);
  EXPECT_EQ(p.waypoints_m()[1][2], 0.0);
  {
    std::ofstream f(path);
    f << "0,0\n0.01,abc\n";
  }
  try {
    ScriptedPath::FromCsv(path, 0.01);
    FAIL() << "bad CSV accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(":2:"), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}

}  // namespace
}  // namespace snapthread::device
