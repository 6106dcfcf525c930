// A killed server resumes on the same branch (issue 12 item 5), with real processes over
// udpm loopback: snapthread-server with --state-dir on curve2d_snap is driven by the
// test's own signed poses past the snap and back to a grasp where both branches exist;
// a snapthread-device holds that grasp; the server is SIGKILLed and restarted on the same
// directory. Its first shape is the pre-kill state (not the scene's start), and the
// device's force comes back to the pre-kill force through the safety ramp, with no step.
// A damaged or truncated checkpoint is refused with a message naming the file and the
// reason, and the server starts fresh.
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "messages/channels.h"
#include "messages/pose_mapping.h"
#include "messages/subscribe.h"
#include "scene/scene.h"
#include "snapthread/device_state_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"
#include "lcm_thread.h"
#include "process_session_test.h"
#include "test_support.h"
#include "tracking/make_tracker.h"

namespace snapthread {
namespace {

using test_support::ChildProcess;
constexpr const char* kUrl = test_support::kLoopbackLcmUrl;
constexpr double kWaitS = 30.0;    // generous: the machine is shared
constexpr double kSameState = 1e-6;
constexpr double kHoldY = 2.4;     // both branches of curve2d_snap exist here
constexpr double kPastSnapY = 3.8;  // the bent-up branch ends near y = 3.42
constexpr int kFadeMs = 100;

std::string Hex(int64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// What the test hears of a session: the newest status (its epoch), every server's first
// shape and the newest shape, and the device_seq of the newest force model answering the
// test's own poses.
class SessionListener {
 public:
  explicit SessionListener(const std::string& session) : lcm_(kUrl), channels_(session) {
    messages::Subscribe<&SessionListener::OnStatus>(lcm_.lcm(), channels_.solver_status, this);
    messages::Subscribe<&SessionListener::OnShape>(lcm_.lcm(), channels_.shape, this);
    messages::Subscribe<&SessionListener::OnModel>(lcm_.lcm(), channels_.force_model, this);
    lcm_.Start();
  }
  ~SessionListener() { lcm_.Stop(); }

  void OnStatus(const lcm::ReceiveBuffer*, const std::string&, const solver_status_t* m) {
    std::lock_guard<std::mutex> lock(mutex_);
    epoch_ = m->epoch;
  }
  void OnShape(const lcm::ReceiveBuffer*, const std::string&, const thread_shape_t* m) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (first_shape_.count(m->epoch) == 0) first_shape_[m->epoch] = *m;
    last_shape_ = *m;
    ++shapes_;
  }
  void OnModel(const lcm::ReceiveBuffer*, const std::string&, const force_model_t* m) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (m->epoch == epoch_ && m->device_seq > answered_) answered_ = m->device_seq;
  }

  // The epoch of the newest status once it is not `old` (0 at the deadline).
  int64_t WaitEpoch(int64_t old = 0) {
    int64_t e = 0;
    test_support::WaitUntil([&] { return (e = Get(&epoch_)) != 0 && e != old; }, kWaitS);
    return e != old ? e : 0;
  }
  // The first shape of the server with this epoch.
  bool FirstShape(int64_t epoch, thread_shape_t* out) {
    return test_support::WaitUntil(
        [&] {
          std::lock_guard<std::mutex> lock(mutex_);
          if (first_shape_.count(epoch) == 0) return false;
          *out = first_shape_[epoch];
          return true;
        },
        kWaitS);
  }
  // A shape published after everything sent so far was solved.
  thread_shape_t SettledShape() {
    const int64_t from = Get(&shapes_);
    test_support::WaitUntil([&] { return Get(&shapes_) >= from + 3; }, kWaitS);
    std::lock_guard<std::mutex> lock(mutex_);
    return last_shape_;
  }
  // One signed pose at grasp u; waits for the force model that answers it.
  bool Pose(const Scene& scene, const Vec& u) {
    const Eigen::Vector3d p = messages::ControlsToPosition(scene.device, scene.grasp_layout, u);
    device_state_t s{};
    s.utime = s.seq = ++seq_;
    s.device_id = "checkpoint-test";
    for (int i = 0; i < 3; ++i) s.position[i] = p[i];
    s.orientation[0] = 1.0;
    s.buttons = 1;
    const auth::KeySet device = auth::KeySet::ForRole(key_->key(), auth::Role::kDevice, "hand");
    if (!auth::Sign(&s, channels_.device_state, Get(&epoch_), auth_seq_.Next(), device.tagger())) return false;
    if (lcm_.lcm().publish(channels_.device_state, &s) != 0) return false;
    return test_support::WaitUntil([&] { return Get(&answered_) >= s.seq; }, kWaitS, 0.0005);
  }
  void set_key(const test_support::SessionKeyFile* key) { key_ = key; }

 private:
  int64_t Get(const int64_t* v) {
    std::lock_guard<std::mutex> lock(mutex_);
    return *v;
  }
  test_support::LcmThread lcm_;
  messages::Channels channels_;
  const test_support::SessionKeyFile* key_ = nullptr;
  auth::AuthSequence auth_seq_;
  int64_t seq_ = 0;
  std::mutex mutex_;
  int64_t epoch_ = 0, answered_ = 0, shapes_ = 0;
  std::map<int64_t, thread_shape_t> first_shape_;
  thread_shape_t last_shape_{};
};

double ShapeDistance(const thread_shape_t& a, const Eigen::Matrix3Xd& nodes) {
  if (a.num_nodes != nodes.cols() || a.num_nodes == 0) return INFINITY;
  double d = 0.0;
  for (int i = 0; i < a.num_nodes; ++i)
    for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(a.positions[i][k] - nodes(k, i)));
  return d;
}

Eigen::Matrix3Xd Nodes(const thread_shape_t& s) {
  Eigen::Matrix3Xd nodes(3, s.num_nodes);
  for (int i = 0; i < s.num_nodes; ++i)
    for (int k = 0; k < 3; ++k) nodes(k, i) = s.positions[i][k];
  return nodes;
}

// The device's trace: per tick the time and the commanded force, and whether it faded.
struct Tick {
  double t_s;
  Eigen::Vector3d f;
  bool fading;
};

std::vector<Tick> ReadTicks(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::map<std::string, size_t> column;
  {
    std::stringstream header(line);
    std::string name;
    for (size_t i = 0; std::getline(header, name, ','); ++i) column[name] = i;
  }
  std::vector<Tick> ticks;
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) v.push_back(std::strtod(cell.c_str(), nullptr));
    if (v.size() != column.size()) continue;
    ticks.push_back({v[column["t_s"]],
                     Eigen::Vector3d(v[column["fx_n"]], v[column["fy_n"]], v[column["fz_n"]]),
                     v[column["fading"]] != 0.0});
  }
  return ticks;
}

class CheckpointProcessTest : public test_support::ProcessSessionTest {
 protected:
  void SetUp() override {
    ASSERT_NO_FATAL_FAILURE(StartSession("CK", "ckpt"));
    state_dir_ = tmp_->path() + "/state";
    scene_path_ = test_support::ScenePath("curve2d_snap.yaml");
    scene_ = LoadScene(scene_path_);
    listener_ = std::make_unique<SessionListener>(session_);
    listener_->set_key(&key_file_);
  }

  std::unique_ptr<ChildProcess> StartServer(const std::string& tag) {
    auto child = std::make_unique<ChildProcess>(
        std::vector<std::string>{bin_ + "/snapthread-server", "--scene", scene_path_, "--session",
                                 session_, "--lcm-url", kUrl, "--state-dir", state_dir_,
                                 "--duration", "300"},
        test_support::OneLog(tmp_->path() + "/server_" + tag + ".log", /*close_stdin=*/true));
    EXPECT_TRUE(child->started());
    EXPECT_TRUE(child->WaitForOutput("server: session", kWaitS)) << child->Out();
    return child;
  }
  void Kill(ChildProcess* server) {
    server->Signal(SIGKILL);
    int code = -1;
    EXPECT_TRUE(server->Wait(10, &code));
    EXPECT_EQ(code, 128 + SIGKILL);
  }
  std::string CheckpointFile() const { return state_dir_ + "/" + session_ + ".checkpoint"; }

  Vec Grasp(double y) const { return (Vec(2) << scene_.grasp_start[0], y).finished(); }
  // The test's poses: up past the snap and back to kHoldY (the bent-down branch).
  void DriveToSecondBranch() {
    auto sweep = [&](double from, double to) {
      const int n = static_cast<int>(std::ceil(std::abs(to - from) / 0.1));
      for (int i = 1; i <= n; ++i) ASSERT_TRUE(listener_->Pose(scene_, Grasp(from + (to - from) * i / n)));
    };
    sweep(scene_.grasp_start[1], kPastSnapY);
    sweep(kPastSnapY, kHoldY);
  }
  // Offline: the state and force (N) at kHoldY on each branch, and the scene's start shape.
  struct Reference {
    Eigen::Matrix3Xd start_nodes;
    Eigen::Vector2d fresh_force_n, snapped_force_n;
  };
  Reference Offline() const {
    Reference r;
    std::unique_ptr<EquilibriumTracker> t = MakeTracker(scene_);
    t->Reset(scene_.grasp_start);
    t->model().NodePositions(t->state(), t->control(), &r.start_nodes);
    auto follow = [&](double from, double to) {
      const int n = static_cast<int>(std::ceil(std::abs(to - from) / 0.1));
      for (int i = 1; i <= n; ++i) t->Update(Grasp(from + (to - from) * i / n));
      return Eigen::Vector2d(scene_.device.newtons_per_model_force * t->last().force.head<2>());
    };
    r.fresh_force_n = follow(scene_.grasp_start[1], kHoldY);
    t->Reset(scene_.grasp_start);
    follow(scene_.grasp_start[1], kPastSnapY);
    r.snapped_force_n = follow(kPastSnapY, kHoldY);
    return r;
  }

  std::string state_dir_, scene_path_;
  Scene scene_;
  std::unique_ptr<SessionListener> listener_;
};

TEST_F(CheckpointProcessTest, AKilledServerResumesOnTheSameBranchAndTheDeviceFeelsNoStep) {
  const Reference ref = Offline();
  ASSERT_GT((ref.fresh_force_n - ref.snapped_force_n).norm(), 0.1)
      << "the two branches must feel different at the held grasp";

  auto server = StartServer("a");
  const int64_t epoch_a = listener_->WaitEpoch();
  ASSERT_NE(epoch_a, 0) << server->Out();
  DriveToSecondBranch();
  const thread_shape_t before = listener_->SettledShape();
  ASSERT_GT(ShapeDistance(before, ref.start_nodes), 0.5) << "not on the second branch";

  // A device holds the grasp (one waypoint) and renders the snapped branch's force.
  const std::string path_csv = tmp_->path() + "/hold.csv";
  {
    const Eigen::Vector3d p =
        messages::ControlsToPosition(scene_.device, scene_.grasp_layout, Grasp(kHoldY));
    std::ofstream(path_csv) << p[0] << "," << p[1] << "," << p[2] << "\n";
  }
  const std::string trace = tmp_->path() + "/trace.csv";
  ChildProcess device({bin_ + "/snapthread-device", "--backend", "sim-path", "--scene", scene_path_,
                       "--path-csv", path_csv, "--session", session_, "--lcm-url", kUrl,
                       "--duration", "120", "--no-rt", "--model-timeout-ms", "50", "--fade-ms",
                       std::to_string(kFadeMs), "--trace", trace},
                      test_support::OneLog(tmp_->path() + "/device.log", true));
  ASSERT_TRUE(device.started());
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // > 5 checkpoint periods
  Kill(server.get());
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the device fades out

  server = StartServer("b");
  const int64_t epoch_b = listener_->WaitEpoch(epoch_a);
  ASSERT_NE(epoch_b, 0) << server->Out();
  thread_shape_t first{};
  ASSERT_TRUE(listener_->FirstShape(epoch_b, &first));
  EXPECT_LT(ShapeDistance(first, Nodes(before)), kSameState) << "first shape after the restart";
  EXPECT_NE(server->Out().find("resumed from checkpoint of epoch " + Hex(epoch_a)), std::string::npos)
      << server->Out();
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  EXPECT_LT(ShapeDistance(listener_->SettledShape(), Nodes(before)), kSameState)
      << "the device's poses at the same grasp keep the branch";
  device.Signal(SIGTERM);
  int code = -1;
  ASSERT_TRUE(device.Wait(10, &code));
  EXPECT_EQ(code, 0) << device.Out();
  server->Signal(SIGTERM);
  EXPECT_TRUE(server->Wait(10, &code));

  // The trace: held force, the fade while no server answered, the fade back in.
  const std::vector<Tick> ticks = ReadTicks(trace);
  ASSERT_GT(ticks.size(), 2000u) << device.Out();
  size_t kill_at = 0;  // the first fading tick after 500 served ones
  for (size_t i = 500; i < ticks.size() && kill_at == 0; ++i) {
    bool served = true;
    for (size_t j = i - 500; j < i && served; ++j) served = !ticks[j].fading;
    if (served && ticks[i].fading) kill_at = i;
  }
  ASSERT_GT(kill_at, 0u) << "no fade when the server was killed";
  size_t resumed_at = kill_at;  // the last served tick before the final fade-out
  for (size_t i = kill_at; i < ticks.size(); ++i)
    if (!ticks[i].fading) resumed_at = i;
  ASSERT_GT(resumed_at, kill_at + 300) << "the restarted server served too briefly";
  const Eigen::Vector2d pre = ticks[kill_at - 1].f.head<2>();
  const Eigen::Vector2d post = ticks[resumed_at].f.head<2>();
  EXPECT_LT((pre - ref.snapped_force_n).norm(), 0.02) << pre.transpose();
  EXPECT_LT((post - pre).norm(), 0.02) << "resumed " << post.transpose() << " vs " << pre.transpose();
  EXPECT_GT((post - ref.fresh_force_n).norm(), 0.08) << "the fresh branch's force";
  // No step beyond the safety ramp: between two ticks the force changes by at most the
  // fade ramp (|F| per fade time) plus 1 mN of solver noise, never by the 1 N slew limit.
  double worst = 0.0;
  for (size_t i = 1; i < ticks.size(); ++i) {
    const double dt = std::max(ticks[i].t_s - ticks[i - 1].t_s, 1e-3);
    const double ramp = pre.norm() * dt / (1e-3 * kFadeMs) + 1e-3;
    const double step = (ticks[i].f - ticks[i - 1].f).norm();
    EXPECT_LE(step, std::min(ramp, 1.0)) << "tick " << i << " at " << ticks[i].t_s << " s";
    worst = std::max(worst, step);
  }
  const auto faded = std::count_if(ticks.begin() + kill_at, ticks.begin() + resumed_at,
                                   [](const Tick& t) { return t.fading; });
  std::printf("held %.4f N (snapped branch %.4f N, fresh %.4f N); resumed %.4f N; largest tick "
              "step %.4f N; %ld ticks faded while no server answered\n",
              pre.norm(), ref.snapped_force_n.norm(), ref.fresh_force_n.norm(), post.norm(), worst,
              static_cast<long>(faded));
}

TEST_F(CheckpointProcessTest, ADamagedOrTruncatedCheckpointIsRefusedAndTheServerStartsFresh) {
  const Reference ref = Offline();
  auto server = StartServer("a");
  int64_t epoch = listener_->WaitEpoch();
  ASSERT_NE(epoch, 0);
  DriveToSecondBranch();
  ASSERT_GT(ShapeDistance(listener_->SettledShape(), ref.start_nodes), 0.5);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  Kill(server.get());

  struct Damage {
    const char* reason;
    void (*apply)(std::string* bytes);
  };
  const Damage damages[] = {
      {"checksum mismatch (the file is damaged)", [](std::string* b) { (*b)[b->size() / 2] ^= 0x04; }},
      {"truncated", [](std::string* b) { b->resize(b->size() / 2); }},
  };
  int tag = 0;
  for (const Damage& damage : damages) {
    std::string bytes = test_support::ReadFile(CheckpointFile());
    ASSERT_GT(bytes.size(), 100u);
    damage.apply(&bytes);
    std::ofstream(CheckpointFile(), std::ios::binary | std::ios::trunc) << bytes;

    server = StartServer("damaged" + std::to_string(tag++));
    const int64_t next = listener_->WaitEpoch(epoch);
    ASSERT_NE(next, 0) << server->Out();
    epoch = next;
    const std::string expected = "checkpoint " + CheckpointFile() + " refused: " + damage.reason;
    EXPECT_NE(server->Out().find(expected), std::string::npos) << server->Out();
    EXPECT_NE(server->Out().find("starting fresh at the start of scene 'curve2d_snap'"),
              std::string::npos);
    thread_shape_t first{};
    ASSERT_TRUE(listener_->FirstShape(epoch, &first));
    EXPECT_LT(ShapeDistance(first, ref.start_nodes), kSameState) << "a fresh start";
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // it checkpoints its start
    Kill(server.get());
  }
}

}  // namespace
}  // namespace snapthread
