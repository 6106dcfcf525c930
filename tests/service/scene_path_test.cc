// One scene -> tracker path (MakeTracker): the sweep and an in-process server over
// an in-memory transport (server_memory_transport.h) follow curve2d_snap through both of its snaps, and every row of the sweep has
// the server's state and force to 1e-12. Before MakeTracker the server kept the default
// snap threshold while the sweep used 0.1 l, so the two could disagree on a scene.
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "messages/pose_mapping.h"
#include "session_key_file.h"
#include "models/models.h"
#include "scene/scene.h"
#include "server.h"
#include "server_memory_transport.h"
#include "sweep.h"
#include "tracking/make_tracker.h"

namespace snapthread::server {
namespace {

using namespace std::chrono_literals;

std::string ScenePath(const std::string& name) {
  const char* dir = std::getenv("SNAPTHREAD_SOURCE_DIR");
  return std::string(dir != nullptr ? dir : "") + "/scenes/" + name;
}

// What the server's tracker held after each update (recorded on its solve thread).
struct ServerRow {
  Vec u, x, force;
  bool snapped = false;
};

class Recorder {
 public:
  void Record(const Vec& u, const EquilibriumTracker& t) {
    std::lock_guard<std::mutex> lock(mutex_);
    rows_.push_back({u, t.state(), t.last().force, t.last().snapped});
    cv_.notify_all();
  }
  bool WaitCount(size_t n) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, 20s, [&] { return rows_.size() >= n; });
  }
  std::vector<ServerRow> rows() {
    std::lock_guard<std::mutex> lock(mutex_);
    return rows_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<ServerRow> rows_;
};

device_state_t Pose(int64_t seq, const Eigen::Vector3d& p) {
  device_state_t s{};
  s.utime = 1000 + seq;
  s.seq = seq;
  s.device_id = "test";
  for (int i = 0; i < 3; ++i) s.position[i] = p[i];
  s.orientation[0] = 1.0;
  s.buttons = 1;
  return s;
}

TEST(ScenePath, SweepAndServerFollowTheSameEquilibria) {
  const std::string file = ScenePath("curve2d_snap.yaml");
  const Scene scene = LoadScene(file);
  Recorder recorder;
  testing::MemoryServerTransport transport;
  const test_support::SessionKeyFile key_file;  // the server's root key
  const auth::KeySet hand = testing::DeviceKeys(key_file.key());  // poses are the device "hand"'s
  auth::AuthSequence auth_seq;
  ServerParams params;
  params.key_path = key_file.path();
  params.session = "PATH";
  params.scene_path = file;
  params.log_level = "warn";
  ServerTestHooks hooks;
  hooks.after_update = [&](const Vec& u, const EquilibriumTracker& t) { recorder.Record(u, t); };
  Server server(params, &transport, std::move(hooks));
  server.Start();

  // Up through the snap at Y ~ 3.4 and back down through the one at Y ~ -3.4, one pose
  // at a time (each answered before the next, so none is dropped).
  const std::vector<Vec> path = PathControls(scene, 120);
  for (size_t i = 1; i < path.size(); ++i) {
    device_state_t s = Pose(static_cast<int64_t>(i), messages::ControlsToPosition(scene.device, scene.grasp_layout, path[i]));
    ASSERT_TRUE(auth::Sign(&s, server.channels().device_state, server.epoch(), auth_seq.Next(), hand.tagger()));
    transport.DeliverDeviceState(test_support::Encode(s));
    ASSERT_TRUE(recorder.WaitCount(i)) << "no update for pose " << i;
  }
  server.Stop();
  const std::vector<ServerRow> served = recorder.rows();
  ASSERT_EQ(served.size(), path.size() - 1);

  // The sweep over exactly the controls the server derived from the poses.
  std::vector<Vec> controls{scene.grasp_start};
  for (const ServerRow& r : served) controls.push_back(r.u);
  auto tracker = MakeTracker(scene);
  const std::vector<SweepRow> rows = RunSweep(tracker.get(), controls);
  ASSERT_EQ(rows.size(), served.size() + 1);
  int snaps = 0;
  for (size_t i = 0; i < served.size(); ++i) {
    const SweepRow& row = rows[i + 1];
    EXPECT_LE((row.state - served[i].x).lpNorm<Eigen::Infinity>(), 1e-12) << "row " << i + 1;
    EXPECT_LE((row.force - served[i].force).lpNorm<Eigen::Infinity>(), 1e-12) << "row " << i + 1;
    EXPECT_EQ(row.snapped, served[i].snapped) << "row " << i + 1;
    if (row.snapped) ++snaps;
  }
  EXPECT_GE(snaps, 2);  // both snaps of the scene
}

// A bad solver option in a scene names the file and the key (MakeTracker turns the
// solver's std::invalid_argument into a SceneError).
TEST(ScenePath, BadLinearSolverNamesFileAndKey) {
  const std::string file = ScenePath("curve2d_snap.yaml");
  const Scene scene = LoadScene(file, {ParseOverride("solver.linear_solver=magic")});
  try {
    MakeTracker(scene);
    FAIL() << "an unknown linear solver was accepted";
  } catch (const SceneError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(file + ": solver.linear_solver: expected one of", 0), 0u) << what;
    EXPECT_NE(what.find("got 'magic'"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace snapthread::server
