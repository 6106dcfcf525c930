// The server in one process over an in-memory transport (server_memory_transport.h): the
// test delivers device states and commands as they would come off the wire and checks
// the force models the server answers with against a direct EquilibriumTracker run, the
// latest-wins rule, commands, and that bad packets are counted and dropped without ever
// publishing a NaN. The LCM transport itself: server_rooms_test.cc.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <latch>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "server_memory_transport.h"

#include "command_message.h"
#include "messages/pose_mapping.h"
#include "server.h"
#include "server_messages.h"
#include "server_probe.h"
#include "models/models.h"
#include "scene/scene.h"
#include "tracking/tracker.h"
#include "messages/validate.h"
#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "environment.h"
#include "session_key_file.h"
#include "temp_dir.h"

namespace snapthread::server {
namespace {

using namespace std::chrono_literals;
using server_test_support::kWait;

using test_support::ScenePath;
using test_support::SourceDir;

using server_test_support::MakePose;
using server_test_support::Probe;

using test_support::MakeCommand;

bool WaitFor(const std::function<bool()>& pred) {
  return test_support::WaitUntil(pred, std::chrono::duration<double>(kWait).count(), 0.002);
}

class ServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(SourceDir().empty()) << "SNAPTHREAD_SOURCE_DIR is not set (run through ctest)";
  }

  void StartServer(const std::string& scene_file, ServerTestHooks hooks = {},
                   const std::string& scene_dir = "") {
    ServerParams params;
    params.session = "MEMQ";
    params.scene_path = ScenePath(scene_file);
    params.scene_dir = scene_dir;
    params.log_level = "warn";
    params.key_path = key_file_.path();
    server_ = std::make_unique<Server>(params, &transport_, std::move(hooks));
    probe_ = std::make_unique<Probe>(&transport_);
    server_->Start();
  }

  // StartServer, and the same scene for the direct tracker the answers are checked against.
  Scene StartServerOn(const std::string& scene_file) {
    StartServer(scene_file);
    return LoadScene(ScenePath(scene_file));
  }

  void TearDown() override {
    if (server_) server_->Stop();
    probe_.reset();
    server_.reset();
  }

  // Tagged by the device "hand" with the server's epoch, as a genuine device does.
  void Publish(const device_state_t& s) {
    transport_.DeliverDeviceState(testing::Tagged(s, server_->channels().device_state, server_->epoch(),
                                                  auth_seq_.Next(), device_.tagger()));
  }
  // Tagged by the operator "ops".
  void Command(int8_t command, const std::string& argument) {
    transport_.DeliverCommand(testing::Tagged(MakeCommand(command, argument), server_->channels().command,
                                              server_->epoch(), auth_seq_.Next(), operator_.tagger()));
  }
  void PublishRaw(const std::string& channel, const std::vector<uint8_t>& bytes) {
    if (channel == server_->channels().command) {
      transport_.DeliverCommand(bytes);
    } else {
      ASSERT_EQ(channel, server_->channels().device_state);
      transport_.DeliverDeviceState(bytes);
    }
  }

  test_support::SessionKeyFile key_file_;
  const auth::KeySet device_ = testing::DeviceKeys(key_file_.key());
  const auth::KeySet operator_ = testing::OperatorKeys(key_file_.key());
  auth::AuthSequence auth_seq_;
  testing::MemoryServerTransport transport_;
  std::unique_ptr<Server> server_;
  std::unique_ptr<Probe> probe_;
};

// Poses from a to b (model controls) in device metres, with a small z offset so the
// planar constraint acts.
std::vector<Eigen::Vector3d> PosesBetween(const Scene& scene, const Vec& a,
                                          const Vec& b, int steps, double z_offset_m) {
  std::vector<Eigen::Vector3d> poses;
  for (int i = 1; i <= steps; ++i) {
    const Vec u = a + (b - a) * (static_cast<double>(i) / steps);
    Vec full = scene.grasp_start;
    full.head(u.size()) = u;
    Eigen::Vector3d p = messages::ControlsToPosition(scene.device, scene.grasp_layout, full);
    p[2] += z_offset_m;
    poses.push_back(p);
  }
  return poses;
}

// Along the first leg of the scene's path.
std::vector<Eigen::Vector3d> PathPoses(const Scene& scene, int steps,
                                       double z_offset_m) {
  return PosesBetween(scene, scene.path.at(0), scene.path.at(1), steps, z_offset_m);
}

TEST_F(ServerTest, ForceModelsMatchDirectTrackerInDeviceUnits) {
  const Scene scene = StartServerOn("curve2d_snap.yaml");
  EquilibriumTracker direct(MakeModel(scene.params), scene.solver);
  direct.Reset(scene.grasp_start);
  const Model& model = direct.model();
  const DeviceMapping& map = scene.device;
  const double z_offset = 0.002;
  // From the start (bent up, y = -3) up past y = 3.42, where the bent-up branch ends in a
  // fold and the strip snaps to bent down (the seed's Fig 2.1 strip, n = 10, X = 9).
  const Vec a = scene.grasp_start;
  const Vec b = (Vec(2) << a[0], 3.8).finished();
  const auto poses = PosesBetween(scene, a, b, 150, z_offset);

  int direct_snaps = 0, server_snaps = 0;
  double max_force_n = 0.0;
  for (size_t i = 0; i < poses.size(); ++i) {
    Publish(MakePose(static_cast<int64_t>(i), poses[i]));
    force_model_t m;
    ASSERT_TRUE(probe_->WaitModel(static_cast<int64_t>(i), &m)) << "no answer to pose " << i;
    const Vec u = messages::PoseToControls(map, scene.grasp_layout, poses[i], Eigen::Vector4d(1, 0, 0, 0));
    const TrackResult& r = direct.Update(u);
    if (r.snapped) ++direct_snaps;
    if (m.status == force_model_t::STATUS_SNAPPED) ++server_snaps;
    ASSERT_NE(m.status, force_model_t::STATUS_INVALID) << "pose " << i;
    const double fs = map.newtons_per_model_force * model.ForceScale();
    const double ks = map.newtons_per_model_force * map.model_units_per_metre;
    for (int a = 0; a < 2; ++a) {
      EXPECT_NEAR(m.f0[a], map.newtons_per_model_force * r.force[a], 1e-9 * (1.0 + fs))
          << "pose " << i << " axis " << a;
      for (int b = 0; b < 2; ++b) {
        EXPECT_NEAR(m.K[a][b], ks * r.stiffness(a, b), 1e-9 * ks * (1.0 + std::abs(r.stiffness(a, b))))
            << "pose " << i;
      }
      EXPECT_EQ(m.K[a][2], 0.0);
    }
    // The virtual plane: f_z = -k (z - z0) with k = max stiffness / 2.
    EXPECT_DOUBLE_EQ(m.K[2][2], -0.5 * map.max_stiffness_n_per_m);
    EXPECT_NEAR(m.f0[2], -0.5 * map.max_stiffness_n_per_m * z_offset, 1e-9);
    for (int a = 0; a < 3; ++a) EXPECT_DOUBLE_EQ(m.u0[a], poses[i][a]);
    EXPECT_EQ(m.device_utime, 1000 + static_cast<int64_t>(i));
    EXPECT_GT(m.server_receive_utime, 0);
    EXPECT_GE(m.solve_us, 0);
    EXPECT_EQ(m.iterations, r.summary.iterations);
    max_force_n = std::max(max_force_n, std::hypot(m.f0[0], m.f0[1]));
  }
  // The path crosses the snap: both runs see it, at the same update.
  EXPECT_GE(direct_snaps, 1);
  EXPECT_EQ(server_snaps, direct_snaps);
  EXPECT_GT(max_force_n, 0.01);
  const ServerStats stats = server_->Stats();
  EXPECT_EQ(stats.updates, static_cast<int64_t>(poses.size()));
  EXPECT_EQ(stats.snaps, direct_snaps);
  EXPECT_EQ(stats.rejected_messages, 0);
  EXPECT_EQ(stats.invalid_models, 0);
  EXPECT_GT(stats.solve_us_p50, 0.0);
  // Shapes and statuses flow at their rates; the shape is the server's current state.
  thread_shape_t shape;
  const size_t since = probe_->num_shapes();
  ASSERT_TRUE(probe_->WaitShape(since, [](const thread_shape_t&) { return true; }, &shape));
  EXPECT_EQ(shape.model, "curve2d");
  EXPECT_EQ(shape.num_nodes, scene.params.Integer("n") + 1);
  EXPECT_NEAR(shape.grasp[0], direct.control()[0], 1e-12);
  EXPECT_NEAR(shape.grasp[1], direct.control()[1], 1e-12);
  EXPECT_EQ(shape.snaps, direct_snaps);
  EXPECT_TRUE(probe_->WaitStatus(0, [&](const solver_status_t& s) {
    return s.updates == static_cast<int64_t>(poses.size()) && s.method == "higher-order" &&
           s.scene == scene.name;
  }));
  EXPECT_EQ(probe_->invalid(), 0);
}

TEST_F(ServerTest, ThreadGripDirectionFromOrientation) {
  const Scene scene = StartServerOn("thread3d_loop.yaml");
  EquilibriumTracker direct(MakeModel(scene.params), scene.solver);
  direct.Reset(scene.grasp_start);
  const Model& model = direct.model();
  ASSERT_EQ(model.NumControls(), 6);
  const Eigen::Vector3d rest = messages::RestGripDirection(scene);
  EXPECT_NEAR((rest - scene.grasp_start.segment<3>(3).normalized()).norm(), 0.0, 1e-15);
  // A device at rest (identity) holds the scene's grip; the last poses turn it by 20
  // degrees about z.
  const double half = 0.5 * 20.0 * M_PI / 180.0;
  const Eigen::Vector4d turned(std::cos(half), 0, 0, std::sin(half));
  const auto poses = PathPoses(scene, 30, 0.0);
  int direct_snaps = 0;
  for (size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Vector4d q = i < 20 ? Eigen::Vector4d(1, 0, 0, 0) : turned;
    Publish(MakePose(static_cast<int64_t>(i), poses[i], q));
    force_model_t m;
    ASSERT_TRUE(probe_->WaitModel(static_cast<int64_t>(i), &m));
    const Vec u = messages::PoseToControls(scene.device, scene.grasp_layout, poses[i], q, rest);
    if (i < 20) {
      EXPECT_NEAR((u.segment<3>(3) - rest).norm(), 0.0, 1e-15);
    }
    const TrackResult& r = direct.Update(u);
    if (r.snapped) ++direct_snaps;
    ASSERT_NE(m.status, force_model_t::STATUS_INVALID);
    EXPECT_EQ(m.has_torque, 1);
    const double n = scene.device.newtons_per_model_force;
    const double s = scene.device.model_units_per_metre;
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(m.f0[a], n * r.force[a], 1e-9 * (1.0 + std::abs(n * r.force[a])));
      for (int b = 0; b < 3; ++b) {
        EXPECT_NEAR(m.K[a][b], n * s * r.stiffness(a, b), 1e-9 * (1.0 + std::abs(n * s * r.stiffness(a, b))));
      }
    }
    const Eigen::Vector3d tau =
        u.segment<3>(3).normalized().cross(Eigen::Vector3d(r.force.segment<3>(3))) * (n / s);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(m.torque0[a], tau[a], 1e-9 * (1.0 + tau.norm()));
  }
  EXPECT_EQ(server_->Stats().snaps, direct_snaps);
  // The knot type (server/knot_watch.h) reaches the status and the shape: a bent thread
  // with free ends, closed far away, is the unknot.
  EXPECT_TRUE(probe_->WaitStatus(0, [](const solver_status_t& st) {
    return st.knot == "unknot" && st.knot_determinant == 1;
  }));
  EXPECT_TRUE(probe_->WaitShape(0, [](const thread_shape_t& sh) { return sh.knot == "unknot"; },
                                nullptr));
  EXPECT_EQ(probe_->invalid(), 0);
}

TEST_F(ServerTest, LatestWinsUnderABurst) {
  // Hold the first update until the whole burst has arrived: the poses in between must be
  // superseded, never queued.
  std::latch entered(1), release(1);
  std::atomic<int> calls{0};
  ServerTestHooks hooks;
  hooks.before_update = [&] {
    if (calls.fetch_add(1) == 0) {
      entered.count_down();
      release.wait();
    }
  };
  StartServer("curve2d_snap.yaml", hooks);
  const Scene scene = LoadScene(ScenePath("curve2d_snap.yaml"));
  auto model = MakeModel(scene.params);
  const auto poses = PathPoses(scene, 50, 0.0);
  Publish(MakePose(0, poses[0]));
  entered.wait();
  for (int i = 1; i < 50; ++i) Publish(MakePose(i, poses[i]));
  // Every pose has reached the inbox before the solver continues.
  ASSERT_TRUE(WaitFor([&] { return server_->Stats().poses_received == 50; }));
  release.count_down();
  force_model_t last;
  ASSERT_TRUE(probe_->WaitModel(49, &last));
  std::this_thread::sleep_for(200ms);  // anything else would have been answered by now
  const auto models = probe_->models();
  EXPECT_LT(models.size(), 50u);
  EXPECT_EQ(models.size(), 2u);  // the pose being solved, then the newest
  EXPECT_EQ(models.front().device_seq, 0);
  EXPECT_EQ(models.back().device_seq, 49);
  const ServerStats stats = server_->Stats();
  EXPECT_EQ(stats.dropped_poses, 48);
  EXPECT_EQ(stats.updates + stats.dropped_poses, 50);
  EXPECT_EQ(probe_->invalid(), 0);
}

TEST_F(ServerTest, LatestWinsWithoutHelp) {
  // No hook: however fast the solver is, the last pose of a burst is answered and every
  // pose is either answered or counted as dropped.
  StartServer("curve2d_snap.yaml");
  const Scene scene = LoadScene(ScenePath("curve2d_snap.yaml"));
  auto model = MakeModel(scene.params);
  const auto poses = PathPoses(scene, 50, 0.0);
  for (int i = 0; i < 50; ++i) Publish(MakePose(i, poses[i]));
  ASSERT_TRUE(probe_->WaitModel(49, nullptr));
  ASSERT_TRUE(WaitFor([&] {
    const ServerStats s = server_->Stats();
    return s.updates + s.dropped_poses == 50;
  }));
  const auto models = probe_->models();
  EXPECT_LE(models.size(), 50u);
  EXPECT_EQ(models.back().device_seq, 49);
  // Answers come in pose order (no stale pose is solved after a newer one).
  for (size_t i = 1; i < models.size(); ++i) EXPECT_GT(models[i].device_seq, models[i - 1].device_seq);
}

TEST_F(ServerTest, CommandsResetSetMethodLoadScene) {
  // LOAD_SCENE takes names from --scene-dir: one with a good and a broken scene.
  const test_support::ScopedTempDir scene_dir("server_scenes");
  {
    std::ofstream(scene_dir.path() + "/zeeman.yaml") << test_support::ReadFile(ScenePath("zeeman.yaml"));
    std::ofstream(scene_dir.path() + "/broken.yaml")
        << "name: broken\nmodel: curve2d\nparams:\n  n: -4\n  frobnicate: 1\n";
  }
  StartServer("curve2d_snap.yaml", {}, scene_dir.path());
  const Scene curve = LoadScene(ScenePath("curve2d_snap.yaml"));
  auto model = MakeModel(curve.params);
  const auto poses = PathPoses(curve, 40, 0.0);
  for (int i = 0; i < 40; ++i) {
    Publish(MakePose(i, poses[i]));
    ASSERT_TRUE(probe_->WaitModel(i, nullptr));
  }

  // RESET: the shape goes back to the scene's start.
  size_t since = probe_->num_shapes();
  Command(command_t::RESET, "");
  ASSERT_TRUE(probe_->WaitShape(since, [&](const thread_shape_t& s) {
    return std::abs(s.grasp[0] - curve.grasp_start[0]) < 1e-12 &&
           std::abs(s.grasp[1] - curve.grasp_start[1]) < 1e-12;
  })) << "no shape at the start after RESET";
  EXPECT_EQ(server_->Stats().commands_applied, 1);
  {
    // After the reset the server tracks from the start again, like a fresh tracker.
    EquilibriumTracker fresh(MakeModel(curve.params), curve.solver);
    fresh.Reset(curve.grasp_start);
    force_model_t m;
    Publish(MakePose(100, poses[0]));
    ASSERT_TRUE(probe_->WaitModel(100, &m));
    const TrackResult& r =
        fresh.Update(messages::PoseToControls(curve.device, curve.grasp_layout, poses[0],
                                               Eigen::Vector4d(1, 0, 0, 0)));
    EXPECT_NEAR(m.f0[0], curve.device.newtons_per_model_force * r.force[0], 1e-9);
    EXPECT_NEAR(m.f0[1], curve.device.newtons_per_model_force * r.force[1], 1e-9);
  }

  // SET_METHOD: a known method is applied, an unknown one refused.
  size_t status_since = probe_->num_statuses();
  Command(command_t::SET_METHOD, "newton");
  ASSERT_TRUE(probe_->WaitStatus(status_since, [](const solver_status_t& s) { return s.method == "newton"; }));
  EXPECT_EQ(server_->Stats().method, "newton");
  Command(command_t::SET_METHOD, "gradient-descent");
  ASSERT_TRUE(WaitFor([&] { return server_->Stats().commands_refused == 1; }));
  EXPECT_EQ(server_->Stats().method, "newton");
  EXPECT_NE(server_->Stats().last_command_message.find("gradient-descent"), std::string::npos);

  // LOAD_SCENE, bad: a missing file and a file with an unknown key are refused with the
  // loader's message; the old scene stays and still answers.
  Command(command_t::LOAD_SCENE, "no_such_scene");
  ASSERT_TRUE(WaitFor([&] { return server_->Stats().commands_refused == 2; }));
  EXPECT_NE(server_->Stats().last_command_message.find("no_such_scene.yaml"), std::string::npos);
  const std::string bad_path = scene_dir.path() + "/broken.yaml";
  Command(command_t::LOAD_SCENE, "broken");
  ASSERT_TRUE(WaitFor([&] { return server_->Stats().commands_refused == 3; }));
  std::string refused;
  try {
    LoadScene(bad_path);
  } catch (const SceneError& e) {
    refused = e.what();
  }
  ASSERT_FALSE(refused.empty()) << "the bad scene should not load";
  EXPECT_NE(server_->Stats().last_command_message.find(refused), std::string::npos)
      << server_->Stats().last_command_message;
  EXPECT_EQ(server_->Stats().scene, curve.name);
  Publish(MakePose(101, poses[1]));
  force_model_t still;
  ASSERT_TRUE(probe_->WaitModel(101, &still));
  EXPECT_NE(still.status, force_model_t::STATUS_INVALID);

  // LOAD_SCENE, good: the zeeman machine, answered like a direct tracker of that scene.
  const Scene zeeman = LoadScene(ScenePath("zeeman.yaml"));
  since = probe_->num_shapes();
  Command(command_t::LOAD_SCENE, "zeeman");
  ASSERT_TRUE(probe_->WaitShape(since, [](const thread_shape_t& s) { return s.model == "zeeman"; }));
  EXPECT_EQ(server_->Stats().scene, zeeman.name);
  // The method override from SET_METHOD survives the new scene.
  EXPECT_EQ(server_->Stats().method, "newton");
  SolverOptions options = zeeman.solver;
  options.method = "newton";
  EquilibriumTracker direct(MakeModel(zeeman.params), options);
  direct.Reset(zeeman.grasp_start);
  const auto zposes = PathPoses(zeeman, 30, 0.0);
  for (int i = 0; i < 30; ++i) {
    Publish(MakePose(200 + i, zposes[i]));
    force_model_t m;
    ASSERT_TRUE(probe_->WaitModel(200 + i, &m));
    const TrackResult& r =
        direct.Update(messages::PoseToControls(zeeman.device, zeeman.grasp_layout, zposes[i],
                                                Eigen::Vector4d(1, 0, 0, 0)));
    for (int a = 0; a < 2; ++a) {
      EXPECT_NEAR(m.f0[a], zeeman.device.newtons_per_model_force * r.force[a], 1e-9) << i;
    }
  }
  EXPECT_EQ(server_->Stats().commands_applied, 3);
  EXPECT_EQ(probe_->invalid(), 0);
}

TEST_F(ServerTest, BadPacketsAreCountedAndDropped) {
  StartServer("curve2d_snap.yaml");
  const messages::Channels& ch = server_->channels();
  int bad = 0;

  auto encode = [](const auto& msg) { return test_support::Encode(msg); };
  const device_state_t good = MakePose(1, Eigen::Vector3d(0.0, 0.0, 0.0));
  const std::vector<uint8_t> good_bytes = encode(good);

  // DEVICE_STATE: garbage, truncated, trailing bytes, oversized, NaN/Inf, bad quaternion,
  // absurd string.
  PublishRaw(ch.device_state, {1, 2, 3});
  ++bad;
  PublishRaw(ch.device_state, std::vector<uint8_t>(good_bytes.begin(), good_bytes.end() - 5));
  ++bad;
  {
    auto trailing = good_bytes;
    trailing.push_back(0);
    PublishRaw(ch.device_state, trailing);
    ++bad;
  }
  {
    std::vector<uint8_t> huge(1 << 20, 0xAB);
    std::copy(good_bytes.begin(), good_bytes.begin() + 8, huge.begin());  // right hash
    PublishRaw(ch.device_state, huge);
    ++bad;
  }
  for (double v : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    device_state_t s = good;
    s.position[1] = v;
    PublishRaw(ch.device_state, encode(s));
    ++bad;
    s = good;
    s.orientation[2] = v;
    PublishRaw(ch.device_state, encode(s));
    ++bad;
  }
  {
    device_state_t s = good;
    for (double& q : s.orientation) q = 0.0;
    PublishRaw(ch.device_state, encode(s));
    ++bad;
    s = good;
    s.device_id = std::string(100000, 'x');
    PublishRaw(ch.device_state, encode(s));
    ++bad;
  }
  // A force model's bytes on the pose channel: wrong fingerprint.
  {
    force_model_t m{};
    PublishRaw(ch.device_state, encode(m));
    ++bad;
  }
  // COMMAND: garbage, unknown command, absurd argument.
  PublishRaw(ch.command, std::vector<uint8_t>(64, 0xFF));
  ++bad;
  PublishRaw(ch.command, encode(MakeCommand(99, "")));
  ++bad;
  PublishRaw(ch.command, encode(MakeCommand(command_t::LOAD_SCENE, std::string(100000, 'y'))));
  ++bad;
  {
    auto truncated = encode(MakeCommand(command_t::RESET, "abc"));
    truncated.resize(truncated.size() - 2);
    PublishRaw(ch.command, truncated);
    ++bad;
  }

  ASSERT_TRUE(WaitFor([&] { return server_->Stats().rejected_messages == bad; }))
      << "rejected " << server_->Stats().rejected_messages << " of " << bad;
  // The solver status reports them (~10 Hz).
  EXPECT_TRUE(probe_->WaitStatus(0, [&](const solver_status_t& s) { return s.rejected_messages == bad; }));
  // The server is alive and answers a good pose; nothing bad reached the solver.
  Publish(good);
  force_model_t m;
  ASSERT_TRUE(probe_->WaitModel(1, &m));
  EXPECT_NE(m.status, force_model_t::STATUS_INVALID);
  const ServerStats stats = server_->Stats();
  EXPECT_EQ(stats.poses_received, 1);
  EXPECT_EQ(stats.updates, 1);
  EXPECT_EQ(stats.commands_applied + stats.commands_refused, 0);
  EXPECT_EQ(stats.rejected_messages, bad);
  EXPECT_EQ(stats.refusals, "unknown/malformed=" + std::to_string(bad));
  EXPECT_EQ(probe_->models().size(), 1u);
  EXPECT_EQ(probe_->invalid(), 0);
}

TEST_F(ServerTest, FarPosesNeverPublishNaN) {
  // Poses across the whole workspace and beyond, in a jumpy order: whatever the solver
  // makes of them, every answer is a valid, finite force model.
  StartServer("curve2d_snap.yaml");
  const double r = 0.3;  // far outside the 8 cm workspace: u up to 15 model units away
  int seq = 0;
  for (double x : {-r, -0.05, 0.0, 0.07, r}) {
    for (double y : {-r, -0.04, 0.0, 0.02, r}) {
      Publish(MakePose(seq, Eigen::Vector3d(x, y, 0.01)));
      ASSERT_TRUE(probe_->WaitModel(seq, nullptr)) << "no answer to " << x << ", " << y;
      ++seq;
    }
  }
  EXPECT_EQ(probe_->models().size(), static_cast<size_t>(seq));
  EXPECT_EQ(probe_->invalid(), 0);
  for (const auto& m : probe_->models()) EXPECT_TRUE(messages::Validate(m, nullptr));
}

}  // namespace
}  // namespace snapthread::server
