// Issue 17 "Done when", as real processes over UDP multicast on loopback:
//   snapthread-server --scene scenes/curve2d_snap.yaml --max-update-hz 100
//   snapthread-device --backend sim-path --speed-m-per-s 0.05 --trace FILE
// The trace shows both snaps within two servo ticks of travel of the true folds (the
// model's continuation, TrueFolds), each a force jump over 0.2 N. The same pair with
// --no-snap-ahead shows the jumps late by up to a server period (printed beside).
#include <signal.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "scene/scene.h"
#include "snap_session.h"
#include "test_support.h"

namespace snapthread::snap_ahead {
namespace {

constexpr double kSpeed = 0.05;
constexpr double kTickTravelM = kSpeed * 1e-3;

std::vector<TickRow> ReadTraceTicks(const std::string& path) {
  std::vector<TickRow> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    double t, x, y, z, fx, fy, fz;
    long long seq;
    if (std::sscanf(line.c_str(), "%lf,%lld,%lf,%lf,%lf,%lf,%lf,%lf", &t, &seq, &x, &y, &z, &fx,
                    &fy, &fz) == 8) {
      rows.push_back({Eigen::Vector3d(x, y, z), Eigen::Vector3d(fx, fy, fz)});
    }
  }
  return rows;
}

class SnapAheadProcessTest : public ::testing::Test {
 protected:
  const test_support::SessionKeyFile key_file_;

  void SetUp() override {
    bin_ = test_support::BinDir();
    source_ = test_support::SourceDir();
    ASSERT_FALSE(bin_.empty() || source_.empty()) << "run through ctest";
    lcm::LCM probe(test_support::kLoopbackLcmUrl);
    ASSERT_TRUE(probe.good()) << "LCM udpm does not start here (deploy/multicast-route.sh)";
    tmp_ = std::make_unique<test_support::ScopedTempDir>("snap_ahead_" + test_support::UniqueSession("SA"));
    scene_path_ = source_ + "/scenes/curve2d_snap.yaml";
  }

  // One pass of the scene's path (there and back) with the server capped at 100 Hz;
  // returns the felt jumps' errors against the true folds, ticks of travel.
  std::vector<double> Run(bool snap_ahead) {
    const std::string tag = snap_ahead ? "ahead" : "late";
    const std::string session = test_support::UniqueSession("SA");
    const std::string dir = tmp_->path();
    std::vector<std::string> server_argv{bin_ + "/snapthread-server", "--scene", scene_path_,
                                         "--max-update-hz", "100", "--session", session,
                                         "--lcm-url", test_support::kLoopbackLcmUrl,
                                         "--duration", "120"};
    std::vector<std::string> device_argv{bin_ + "/snapthread-device", "--backend", "sim-path",
                                         "--scene", scene_path_, "--speed-m-per-s", "0.05",
                                         "--trace", dir + "/trace_" + tag + ".csv", "--session",
                                         session, "--lcm-url", test_support::kLoopbackLcmUrl,
                                         "--duration", "6.6", "--no-rt"};
    if (!snap_ahead) {
      server_argv.push_back("--no-snap-ahead");
      device_argv.push_back("--no-snap-ahead");
    }
    test_support::ChildProcess server(server_argv, test_support::OneLog(dir + "/server_" + tag + ".log", true));
    EXPECT_TRUE(server.WaitForOutput("server: session", 30)) << server.Out();
    test_support::ChildProcess device(device_argv, test_support::OneLog(dir + "/device_" + tag + ".log", true));
    int code = -1;
    EXPECT_TRUE(device.Wait(120, &code)) << "device did not finish";
    EXPECT_EQ(code, 0) << device.Out();
    server.Signal(SIGTERM);
    EXPECT_TRUE(server.Wait(60, &code));

    const Scene scene = LoadScene(scene_path_);
    const std::vector<Eigen::Vector3d> folds = TrueFolds(scene, 0.01);
    EXPECT_EQ(folds.size(), 2u);
    const std::vector<TickRow> ticks = ReadTraceTicks(dir + "/trace_" + tag + ".csv");
    EXPECT_GT(ticks.size(), 5000u);
    const std::vector<ForceJump> jumps = ForceJumps(ticks, 0.1, 300);
    EXPECT_EQ(jumps.size(), folds.size()) << tag << ": " << device.Out();
    std::vector<double> errors;
    for (size_t k = 0; k < jumps.size() && k < folds.size(); ++k) {
      const int t = jumps[k].tick;
      const Eigen::Vector3d v = (ticks[t].position_m - ticks[t - 1].position_m).normalized();
      errors.push_back((jumps[k].position_m - folds[k]).dot(v) / kTickTravelM);
      EXPECT_GT(jumps[k].size_n, 0.2) << tag << " snap " << k + 1;
      std::printf("%s: snap %zu felt %+.2f ticks of travel from the fold, jump %.2f N\n",
                  tag.c_str(), k + 1, errors.back(), jumps[k].size_n);
    }
    return errors;
  }

  std::unique_ptr<test_support::ScopedTempDir> tmp_;
  std::string bin_, source_, scene_path_;
};

TEST_F(SnapAheadProcessTest, BothSnapsWithinTwoTicksAt100HzAndAboutAPeriodLateWithout) {
  const std::vector<double> ahead = Run(true);
  ASSERT_EQ(ahead.size(), 2u);
  for (double e : ahead) EXPECT_LE(std::abs(e), 2.0) << "snap-ahead: felt at the fold";
  const std::vector<double> late = Run(false);
  ASSERT_EQ(late.size(), 2u);
  // A pose past the fold waits for the next 100 Hz update, then the round trip: late by
  // up to a period (10 ticks) and a few ticks of latency, never early.
  for (double e : late) {
    EXPECT_GE(e, 0.0);
    EXPECT_LE(e, 25.0);
  }
  EXPECT_GT(0.5 * (late[0] + late[1]), 2.0) << "without snap-ahead the jumps come late";
}

}  // namespace
}  // namespace snapthread::snap_ahead
