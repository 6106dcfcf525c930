// The server's checkpoints in one process over an in-memory transport: a server driven
// past the snap of curve2d_snap and back to a grasp where both branches exist is stopped;
// a new server on the same --state-dir starts on the snapped branch (not the scene's
// start), with a new epoch; LOAD_SCENE and SET_METHOD are resumed; a refused checkpoint
// (damaged, another key, a state that does not fit the scene's model, a NaN, a scene that
// does not load) is logged with the file and the reason and the server starts fresh; a
// writer stuck on a slow disk never holds up the force models.
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "checkpoint.h"
#include "command_message.h"
#include "environment.h"
#include "messages/pose_mapping.h"
#include "messages/validate.h"
#include "scene/scene.h"
#include "server.h"
#include "server_memory_transport.h"
#include "session_key_file.h"
#include "snapthread/thread_shape_t.hpp"
#include "temp_dir.h"
#include "tracking/make_tracker.h"

namespace snapthread::server {
namespace {

constexpr double kWaitS = 20.0;  // generous: the machine is shared
constexpr double kSameState = 1e-6;

// The grasp y of curve2d_snap where the test stops: the bent-up branch (from the start,
// y = -4) and the bent-down one (after the snap near y = 3.42) both exist there.
constexpr double kHoldY = 2.4;
constexpr double kPastSnapY = 3.8;

// Largest coordinate difference of two shapes' node positions (inf for different sizes).
double ShapeDistance(const thread_shape_t& a, const thread_shape_t& b) {
  if (a.num_nodes != b.num_nodes || a.num_nodes == 0) return INFINITY;
  double d = 0.0;
  for (int i = 0; i < a.num_nodes; ++i)
    for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(a.positions[i][k] - b.positions[i][k]));
  return d;
}

class ServerCheckpointTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = LoadScene(test_support::ScenePath("curve2d_snap.yaml"));
    previous_logger_ = spdlog::default_logger();
    ResetLog();
  }
  // The server's log lines from now on (spdlog's default logger).
  void ResetLog() {
    log_ = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(256);
    spdlog::set_default_logger(std::make_shared<spdlog::logger>("checkpoint_test", log_));
  }
  void TearDown() override {
    StopServer();
    spdlog::set_default_logger(previous_logger_);
  }

  ServerParams Params() const {
    ServerParams p;
    p.session = "CKPT";
    p.scene_path = test_support::ScenePath("curve2d_snap.yaml");
    p.key_path = key_file_.path();
    p.state_dir = state_.path() + "/state";
    return p;
  }
  std::string CheckpointFile() const { return CheckpointPath(Params().state_dir, "CKPT"); }

  void StartServer(ServerParams params, ServerTestHooks hooks = {}) {
    if (!hooks.after_update) {
      hooks.after_update = [this](const Vec&, const EquilibriumTracker& t) {
        std::lock_guard<std::mutex> lock(mutex_);
        last_state_ = t.state();
      };
    }
    // A new transport per server (a restarted process), listened to before it starts.
    transport_ = std::make_unique<testing::MemoryServerTransport>();
    transport_->AddListener([this](testing::Outbound channel, const std::vector<uint8_t>& bytes) {
      thread_shape_t shape;
      if (channel == testing::Outbound::kShape &&
          messages::DecodeAndValidate(bytes.data(), static_cast<int>(bytes.size()), &shape, nullptr)) {
        OnShape(shape);
      }
    });
    server_ = std::make_unique<Server>(params, transport_.get(), std::move(hooks));
    server_->Start();
  }
  void StartServer() { StartServer(Params()); }
  void StopServer() {
    if (!server_) return;
    server_->Stop();
    server_.reset();
    transport_.reset();
  }

  void OnShape(const thread_shape_t& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (first_shapes_.count(msg.epoch) == 0) first_shapes_[msg.epoch] = msg;
    last_shape_ = msg;
    ++shapes_;
  }
  // The first shape the running server published.
  thread_shape_t FirstShape() {
    const int64_t epoch = server_->epoch();
    EXPECT_TRUE(test_support::WaitUntil(
        [&] {
          std::lock_guard<std::mutex> lock(mutex_);
          return first_shapes_.count(epoch) > 0;
        },
        kWaitS));
    std::lock_guard<std::mutex> lock(mutex_);
    return first_shapes_[epoch];
  }
  // A shape published after everything so far was solved.
  thread_shape_t SettledShape() {
    int64_t from = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      from = shapes_;
    }
    EXPECT_TRUE(test_support::WaitUntil(
        [&] {
          std::lock_guard<std::mutex> lock(mutex_);
          return shapes_ >= from + 2;
        },
        kWaitS));
    std::lock_guard<std::mutex> lock(mutex_);
    return last_shape_;
  }
  Vec LastState() {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_state_;
  }

  // One signed pose at grasp (X, y); waits until the server has solved it.
  void Pose(double y) {
    const Vec u = (Vec(2) << scene_.grasp_start[0], y).finished();
    const Eigen::Vector3d p = messages::ControlsToPosition(scene_.device, scene_.grasp_layout, u);
    device_state_t s{};
    s.utime = ++pose_seq_;
    s.seq = pose_seq_;
    s.device_id = "test";
    for (int i = 0; i < 3; ++i) s.position[i] = p[i];
    s.orientation[0] = 1.0;
    s.buttons = 1;
    ASSERT_TRUE(auth::Sign(&s, server_->channels().device_state, server_->epoch(),
                           auth_seq_.Next(), device_.tagger()));
    const int64_t before = server_->Stats().updates;
    transport_->DeliverDeviceState(test_support::Encode(s));
    ASSERT_TRUE(test_support::WaitUntil([&] { return server_->Stats().updates > before; }, kWaitS,
                                        0.0005));
  }
  void Sweep(double from, double to, double step = 0.1) {
    const int n = static_cast<int>(std::ceil(std::abs(to - from) / step));
    for (int i = 1; i <= n; ++i) Pose(from + (to - from) * i / n);
  }
  // Up past the snap and back to kHoldY: the bent-down branch.
  void DriveToSecondBranch() {
    Sweep(scene_.grasp_start[1], kPastSnapY);
    Sweep(kPastSnapY, kHoldY);
  }

  // The fresh server's shape: the scene's start state.
  thread_shape_t FreshStartShape() {
    ServerParams p = Params();
    p.state_dir.clear();
    StartServer(p);
    const thread_shape_t shape = FirstShape();
    StopServer();
    return shape;
  }

  bool Logged(const std::string& text) const {
    for (const std::string& line : log_->last_formatted())
      if (line.find(text) != std::string::npos) return true;
    return false;
  }
  std::string LogText() const {
    std::string all;
    for (const std::string& line : log_->last_formatted()) all += line;
    return all;
  }

  // A checkpoint a key holder wrote (the scene's own text) with `edit` applied.
  void WriteSigned(const std::function<void(Checkpoint*)>& edit) {
    Checkpoint c;
    c.epoch = 77;
    c.scene_name = scene_.name;
    c.scene_file = scene_.file;
    c.scene_text = test_support::ReadFile(scene_.file);
    c.method = scene_.solver.method;
    c.u = scene_.grasp_start;
    std::unique_ptr<EquilibriumTracker> t = MakeTracker(scene_);
    t->Reset(scene_.grasp_start);
    c.x = t->state();
    edit(&c);
    PrepareStateDir(Params().state_dir);
    WriteFileAtomically(CheckpointFile(), EncodeCheckpoint(c, key_file_.key()));
  }

  test_support::SessionKeyFile key_file_;
  const auth::KeySet device_ = testing::DeviceKeys(key_file_.key());
  const auth::KeySet operator_ = testing::OperatorKeys(key_file_.key());
  test_support::ScopedTempDir state_{"server-checkpoint"};
  std::unique_ptr<testing::MemoryServerTransport> transport_;
  Scene scene_;
  std::unique_ptr<Server> server_;
  auth::AuthSequence auth_seq_;
  int64_t pose_seq_ = 0;
  std::mutex mutex_;
  std::map<int64_t, thread_shape_t> first_shapes_;
  thread_shape_t last_shape_{};
  int64_t shapes_ = 0;
  Vec last_state_;
  std::shared_ptr<spdlog::sinks::ringbuffer_sink_mt> log_;
  std::shared_ptr<spdlog::logger> previous_logger_;
};

TEST_F(ServerCheckpointTest, RestartResumesOnTheSnappedBranchWithANewEpoch) {
  const thread_shape_t fresh = FreshStartShape();
  StartServer();
  EXPECT_TRUE(Logged("no checkpoint " + CheckpointFile())) << LogText();
  DriveToSecondBranch();
  EXPECT_GE(server_->Stats().snaps, 1);
  const Vec saved_state = LastState();
  const thread_shape_t before = SettledShape();
  const int64_t first_epoch = server_->epoch();
  StopServer();  // a clean stop writes the last state

  // Two branches at the same grasp: a fresh start followed to kHoldY stays bent up.
  std::unique_ptr<EquilibriumTracker> reference = MakeTracker(scene_);
  reference->Reset(scene_.grasp_start);
  for (double y = scene_.grasp_start[1]; y < kHoldY; y += 0.1)
    reference->Update((Vec(2) << scene_.grasp_start[0], y).finished());
  reference->Update((Vec(2) << scene_.grasp_start[0], kHoldY).finished());
  ASSERT_GT((reference->state() - saved_state).lpNorm<Eigen::Infinity>(), 0.5)
      << "the test must stop where the two branches differ";

  StartServer();
  EXPECT_TRUE(server_->Stats().resumed);
  EXPECT_NE(server_->epoch(), first_epoch) << "every start draws a new epoch";
  const thread_shape_t after = FirstShape();
  EXPECT_LT(ShapeDistance(after, before), kSameState);
  EXPECT_GT(ShapeDistance(after, fresh), 0.5);
  EXPECT_NEAR(after.grasp[1], kHoldY, 1e-9);
  char epoch_hex[17];
  std::snprintf(epoch_hex, sizeof(epoch_hex), "%016llx", static_cast<unsigned long long>(first_epoch));
  EXPECT_TRUE(Logged(std::string("resumed from checkpoint of epoch ") + epoch_hex)) << LogText();

  // The next pose at the same grasp keeps the saved state.
  Pose(kHoldY);
  EXPECT_LT((LastState() - saved_state).lpNorm<Eigen::Infinity>(), kSameState);
  // Moving on from there follows the bent-down branch (no snap back up).
  Sweep(kHoldY, 0.0);
  EXPECT_EQ(server_->Stats().snaps, 0);
}

TEST_F(ServerCheckpointTest, LoadedSceneAndSwitchedMethodAreResumed) {
  StartServer();
  auto command = [&](int8_t code, const std::string& argument, int64_t applied) {
    command_t c = test_support::MakeCommand(code, argument);
    ASSERT_TRUE(auth::Sign(&c, server_->channels().command, server_->epoch(), auth_seq_.Next(),
                           operator_.tagger()));
    transport_->DeliverCommand(test_support::Encode(c));
    ASSERT_TRUE(test_support::WaitUntil(
        [&] { return server_->Stats().commands_applied >= applied; }, kWaitS));
  };
  command(command_t::SET_METHOD, "newton-ls", 1);
  command(command_t::LOAD_SCENE, "zeeman", 2);
  ASSERT_EQ(server_->Stats().scene, "zeeman");
  StopServer();

  StartServer();  // --scene still names curve2d_snap
  const ServerStats s = server_->Stats();
  EXPECT_TRUE(s.resumed);
  EXPECT_EQ(s.scene, "zeeman");
  EXPECT_EQ(s.method, "newton-ls");
  EXPECT_EQ(FirstShape().model, "zeeman");
}

TEST_F(ServerCheckpointTest, ARefusedCheckpointIsLoggedWithItsReasonAndTheServerStartsFresh) {
  const thread_shape_t fresh = FreshStartShape();
  struct Case {
    const char* name;
    std::function<void()> make;
    const char* reason;
  };
  const std::string file = CheckpointFile();
  auto good_bytes = [&] {
    WriteSigned([](Checkpoint*) {});
    return test_support::ReadFile(file);
  };
  auto write_raw = [&](const std::string& bytes) {
    std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
  };
  const std::vector<Case> cases = {
      {"truncated", [&] { write_raw(good_bytes().substr(0, 100)); }, "truncated"},
      {"bad magic", [&] { write_raw("NOTACKPT" + good_bytes().substr(8)); }, "bad magic"},
      {"flipped byte",
       [&] {
         std::string b = good_bytes();
         b[40] ^= 0x10;
         write_raw(b);
       },
       "checksum mismatch"},
      {"another key",
       [&] {
         Checkpoint c;
         c.method = "newton";
         write_raw(EncodeCheckpoint(c, auth::SessionKey::Generate()));
       },
       "not written with this session key"},
      {"NaN in the state", [&] { WriteSigned([](Checkpoint* c) { c->x[2] = NAN; }); },
       "non-finite value in the state x[2]"},
      {"state size",
       [&] { WriteSigned([](Checkpoint* c) { c->x.conservativeResize(c->x.size() - 1); }); },
       "its state has"},
      {"scene", [&] { WriteSigned([](Checkpoint* c) { c->scene_text = "model: [unclosed"; }); },
       "its scene does not load"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    c.make();
    ResetLog();
    StartServer();
    EXPECT_FALSE(server_->Stats().resumed);
    EXPECT_TRUE(Logged("checkpoint " + file + " refused: " + c.reason)) << LogText();
    EXPECT_TRUE(Logged("starting fresh at the start of scene 'curve2d_snap'")) << LogText();
    EXPECT_LT(ShapeDistance(FirstShape(), fresh), kSameState);
    StopServer();  // writes a valid checkpoint of the fresh start
    std::string reason;
    std::string bytes;
    ASSERT_EQ(ReadCheckpointFile(file, &bytes, &reason), ReadStatus::kOk);
    EXPECT_TRUE(DecodeCheckpoint(bytes, key_file_.key(), nullptr, &reason)) << reason;
  }
}

// The writer's gate: a disk that does not return until Open().
class SlowDisk {
 public:
  void Write() {
    waiting_.fetch_add(1);
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [&] { return open_; });
  }
  void Open() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      open_ = true;
    }
    cv_.notify_all();
  }
  int waiting() const { return waiting_.load(); }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool open_ = false;
  std::atomic<int> waiting_{0};
};

TEST_F(ServerCheckpointTest, ASlowDiskNeverHoldsUpTheForceModels) {
  SlowDisk disk;
  // Opens the disk and stops the server before `disk` goes, whatever the test asserted.
  struct AtExit {
    std::function<void()> run;
    ~AtExit() { run(); }
  } release{[&] {
    disk.Open();
    StopServer();
  }};
  ServerTestHooks hooks;
  hooks.before_checkpoint_write = [&disk] { disk.Write(); };
  StartServer(Params(), std::move(hooks));
  // The writer is stuck in its first write; for half a second the server keeps answering
  // every pose and handing over snapshots.
  ASSERT_TRUE(test_support::WaitUntil([&] { return disk.waiting() >= 1; }, kWaitS));
  const auto t0 = std::chrono::steady_clock::now();
  int poses = 0;
  while (std::chrono::steady_clock::now() - t0 < std::chrono::milliseconds(500)) {
    Pose(scene_.grasp_start[1] + 0.002 * (poses++ % 200));
  }
  ServerStats s = server_->Stats();
  EXPECT_GE(s.updates, poses);
  EXPECT_EQ(s.checkpoint.written, 0);
  EXPECT_GE(s.checkpoint.offered, 3);
  disk.Open();
  // Released: the writer skips to the newest snapshot, and goes on at >= 5 Hz while the
  // state changes.
  ASSERT_TRUE(test_support::WaitUntil([&] { return server_->Stats().checkpoint.written >= 1; }, kWaitS));
  const int64_t written_before = server_->Stats().checkpoint.written;
  const auto t1 = std::chrono::steady_clock::now();
  double y = scene_.grasp_start[1];
  while (std::chrono::steady_clock::now() - t1 < std::chrono::seconds(2)) {
    y = y > -3.0 ? scene_.grasp_start[1] : y + 0.01;
    Pose(y);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const double span_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  s = server_->Stats();
  const double rate_hz = static_cast<double>(s.checkpoint.written - written_before) / span_s;
  EXPECT_GE(rate_hz, 5.0);
  EXPECT_EQ(s.checkpoint.failed, 0);
  std::printf("checkpoints: %.1f written/s while moving; write p50 %.0f us, p99 %.0f us, max %.0f us; "
              "solve-thread snapshot p50 %.1f us, p99 %.1f us\n",
              rate_hz, s.checkpoint.write_us_p50, s.checkpoint.write_us_p99, s.checkpoint.write_us_max,
              s.checkpoint_offer_us_p50, s.checkpoint_offer_us_p99);
}

}  // namespace
}  // namespace snapthread::server
