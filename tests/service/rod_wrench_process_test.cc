// Issue 14 item 3, live: snapthread-server on scenes/rod_greenhill.yaml and
// snapthread-device (sim-path, which follows the scene path's roll and renders torque)
// as separate processes over UDP multicast on loopback. The device receives 6-DoF
// (has_wrench) models and, before the buckle, the torque it commands about the rod's
// axis is the straight twisted rod's -GJ Φ / L through the device mapping, clamped at
// --max-torque-nm.
#include <signal.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "process_session_test.h"
#include "scene/scene.h"
#include "test_support.h"

namespace snapthread {
namespace {

using test_support::ChildProcess;
constexpr const char* kUrl = test_support::kLoopbackLcmUrl;

class RodWrenchProcess : public test_support::ProcessSessionTest {
 protected:
  void SetUp() override { ASSERT_NO_FATAL_FAILURE(StartSession("RW", "rod_wrench")); }
};

TEST_F(RodWrenchProcess, DeviceRendersTheTwistTorqueBeforeTheBuckle) {
  const std::string& bin = bin_;
  const std::string& session = session_;
  const std::string dir = tmp_->path();
  const std::string scene_path = test_support::ScenePath("rod_greenhill.yaml");
  const Scene scene = LoadScene(scene_path);
  const int n = scene.params.Integer("n");
  const double gj = scene.params.Number("twist_stiffness");
  const double length = scene.params.Number("length");
  // N m per model energy unit: newtons per model force over model units per metre.
  const double units = scene.device.newtons_per_model_force / scene.device.model_units_per_metre;
  const double max_torque = 0.05;
  // 90 degrees a second for 4.5 s: up to 405 degrees, short of Greenhill's 515; the
  // clamp acts past about 270 degrees.
  const double angular_speed_deg = 90.0, duration_s = 4.5;

  ChildProcess server({bin + "/snapthread-server", "--scene", scene_path, "--session", session, "--lcm-url", kUrl,
                       "--summary", dir + "/server.json", "--duration", "300"},
                      test_support::OneLog(dir + "/server.log", true));
  ASSERT_TRUE(server.started());
  ASSERT_TRUE(server.WaitForOutput("server: session", 30)) << server.Out();
  ChildProcess device({bin + "/snapthread-device", "--backend", "sim-path", "--scene", scene_path,
                       "--angular-speed-deg-per-s", std::to_string(angular_speed_deg), "--max-torque-nm",
                       std::to_string(max_torque), "--session", session, "--lcm-url", kUrl, "--duration",
                       std::to_string(duration_s), "--rate-hz", "1000", "--no-rt", "--trace", dir + "/trace.csv",
                       "--summary", dir + "/device.json"},
                      test_support::OneLog(dir + "/device.log", true));
  ASSERT_TRUE(device.started());
  int code = -1;
  ASSERT_TRUE(device.Wait(120, &code)) << "device did not finish";
  EXPECT_EQ(code, 0) << device.Out();
  server.Signal(SIGTERM);
  ASSERT_TRUE(server.Wait(60, &code));
  EXPECT_EQ(code, 0) << server.Out();

  auto dev = test_support::ReadJsonNumbers(dir + "/device.json");
  ASSERT_GT(dev.count("ticks"), 0u);
  // Models per tick is the server's solve speed: a slower (sanitized) build divides it.
  EXPECT_GT(dev["wrench_models"], 0.5 / test_support::SpeedScale() * dev["ticks"]) << device.Out();
  EXPECT_EQ(dev["wrench_models"], dev["models_received"]);
  EXPECT_EQ(dev["nonfinite_outputs"], 0);
  EXPECT_GT(dev["torque_clamps"], 0);

  // Settled rows: a fresh regular model and no stale tick within the fade time (the fade
  // gain is 1). The roll is unwrapped along the trace (the path only rolls forward).
  const std::vector<test_support::DeviceTraceRow> rows = test_support::ReadDeviceTrace(dir + "/trace.csv");
  ASSERT_GT(rows.size(), 1000u);
  const double fade_s = 0.100;
  double last_unsettled = 0.0, roll = 0.0, previous = 0.0;
  int settled = 0, lawful = 0, clamped = 0;
  for (const test_support::DeviceTraceRow& r : rows) {
    const double angle = 2.0 * std::atan2(r.orientation[1], r.orientation[0]);  // the sim hand rolls about x
    roll += std::remainder(angle - previous, 2.0 * std::numbers::pi);
    previous = angle;
    if (r.model_age_ms < 0.0 || r.fading || r.model_status != 0) {
      last_unsettled = r.t_s;
      continue;
    }
    if (r.model_age_ms > 20.0 || r.t_s - last_unsettled < fade_s + 0.005) continue;
    ++settled;
    // The discrete rod's twist acts over (n - 1) edges (tests/rod_scene_test.cc).
    const double free_torque = units * gj * roll / length * n / (n - 1.0);
    const double expected = -std::min(free_torque, max_torque);
    if (free_torque > max_torque) ++clamped;
    // Linear in the roll for the straight rod, so the 6-DoF local model is exact to the
    // trace's 9 digits at any model age; 1e-6 N m covers the rod's 1e-6 imperfection.
    const bool ok = std::abs(r.torque_nm[0] - expected) < 1e-6 + 1e-4 * std::abs(expected) &&
                    std::hypot(r.torque_nm[1], r.torque_nm[2]) < 1e-6 + 1e-4 * std::abs(expected);
    lawful += ok ? 1 : 0;
    if (!ok && settled - lawful < 5) {
      std::printf("t = %.3f s, roll %.4f rad: torque (%.6g, %.3g, %.3g) N m, expected %.6g\n", r.t_s, roll, r.torque_nm[0],
                  r.torque_nm[1], r.torque_nm[2], expected);
    }
  }
  std::printf("rod_wrench: %d settled ticks, %d lawful, %d clamped; roll reached %.1f degrees\n", settled, lawful,
              clamped, roll * 180.0 / std::numbers::pi);
  EXPECT_GT(settled, 1000);
  EXPECT_GT(clamped, 100);
  EXPECT_GT(settled - clamped, 1000);
  EXPECT_GE(lawful, 0.99 * settled);
}

}  // namespace
}  // namespace snapthread
