// Commands from the network, the server in one process over an in-memory transport:
// LOAD_SCENE by name only from --scene-dir (every way out of the directory refused and
// counted), loads off the solve thread with a time limit while force models keep flowing,
// and --allow-methods.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "command_message.h"
#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "session_key_file.h"
#include "arrival_log.h"
#include "environment.h"
#include "messages/pose_mapping.h"
#include "messages/validate.h"
#include "scene/scene.h"
#include "scene_dir.h"
#include "server.h"
#include "server_memory_transport.h"
#include "temp_dir.h"

namespace snapthread::server {
namespace {

using Clock = std::chrono::steady_clock;
using test_support::ScenePath;

constexpr double kWaitS = 20.0;  // generous: the machine is shared

using test_support::MakeCommand;

// A server in memory answering a pose stream at ~200 Hz; records when each force model
// arrives so a test can bound the longest gap.
class CommandsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_dir_ = std::make_unique<test_support::ScopedTempDir>("scene_dir");
    CopyScene("zeeman.yaml");
  }

  void TearDown() override {
    StopPoses();
    if (server_) server_->Stop();
    server_.reset();
  }

  const std::string& dir() const { return scene_dir_->path(); }
  void CopyScene(const std::string& file) {
    std::ofstream(dir() + "/" + file) << test_support::ReadFile(ScenePath(file));
  }

  void StartServer(ServerParams params = {}, ServerTestHooks hooks = {}) {
    params.session = "MEMQ";
    params.scene_path = ScenePath("curve2d_snap.yaml");
    params.scene_dir = dir();
    params.log_level = "off";
    params.key_path = key_file_.path();
    server_ = std::make_unique<Server>(params, &transport_, std::move(hooks));
    transport_.AddListener([this](testing::Outbound channel, const std::vector<uint8_t>& bytes) {
      if (channel == testing::Outbound::kForceModel) arrivals_.Mark();
      if (channel == testing::Outbound::kCommandReply) KeepReply(bytes);
    });
    server_->Start();
    const Scene scene = LoadScene(params.scene_path);
    pose_ = messages::ControlsToPosition(scene.device, scene.grasp_layout, scene.grasp_start);
    poser_ = std::thread([this] {
      int64_t seq = 0;
      while (!stop_poses_.load()) {
        device_state_t s;
        s.utime = 1000 + seq;
        s.seq = seq++;
        s.device_id = "test";
        for (int i = 0; i < 3; ++i) s.position[i] = pose_[i];
        for (int i = 0; i < 4; ++i) s.orientation[i] = i == 0 ? 1.0 : 0.0;
        s.buttons = 1;
        transport_.DeliverDeviceState(testing::Tagged(s, server_->channels().device_state, server_->epoch(),
                                                      auth_seq_.Next(), device_.tagger()));
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    });
    ASSERT_TRUE(test_support::WaitUntil([&] { return Models() > 20; }, kWaitS, 0.002));
  }

  void StopPoses() {
    stop_poses_ = true;
    if (poser_.joinable()) poser_.join();
  }

  size_t Models() { return arrivals_.count(); }
  double MaxGapSince(size_t from) { return arrivals_.MaxGapSince(from); }

  // Sends a command tagged by `sender` (the session's operator by default); returns its auth_seq.
  int64_t Command(int8_t command, const std::string& argument, const auth::KeySet* sender = nullptr) {
    command_t c = MakeCommand(command, argument);
    const int64_t seq = auth_seq_.Next();
    transport_.DeliverCommand(testing::Tagged(c, server_->channels().command, server_->epoch(), seq,
                                              (sender != nullptr ? *sender : operator_).tagger()));
    return seq;
  }
  // A reply as a console checks it: it decodes, validates and carries the server's
  // signature (the session's server public key).
  void KeepReply(const std::vector<uint8_t>& bytes) {
    command_reply_t reply;
    std::string why;
    const bool valid =
        messages::DecodeAndValidate(bytes.data(), static_cast<int>(bytes.size()), &reply, &why) &&
        auth::VerifySignature(bytes.data(), bytes.size(), server_->channels().command_reply,
                              operator_.server_public_key());
    std::lock_guard<std::mutex> lock(mutex_);
    if (valid) {
      replies_.push_back(reply);
    } else {
      ++invalid_replies_;
    }
  }
  // The reply answering auth_seq `seq`, waited for.
  std::optional<command_reply_t> ReplyTo(int64_t seq, double timeout_s = kWaitS) {
    std::optional<command_reply_t> found;
    test_support::WaitUntil([&] {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const auto& r : replies_) {
        if (r.command_auth_seq == seq) found = r;
      }
      return found.has_value();
    }, timeout_s, 0.002);
    return found;
  }
  bool WaitRefused(int64_t n) {
    return test_support::WaitUntil([&] { return server_->Stats().commands_refused >= n; }, kWaitS,
                                   0.002);
  }
  bool WaitApplied(int64_t n) {
    return test_support::WaitUntil([&] { return server_->Stats().commands_applied >= n; }, kWaitS,
                                   0.002);
  }

  test_support::SessionKeyFile key_file_;
  const auth::KeySet device_ = testing::DeviceKeys(key_file_.key());
  const auth::KeySet operator_ = testing::OperatorKeys(key_file_.key());
  auth::AuthSequence auth_seq_;
  testing::MemoryServerTransport transport_;
  std::unique_ptr<test_support::ScopedTempDir> scene_dir_;
  std::unique_ptr<Server> server_;
  Eigen::Vector3d pose_ = Eigen::Vector3d::Zero();
  std::thread poser_;
  std::atomic<bool> stop_poses_{false};
  std::mutex mutex_;
  std::vector<command_reply_t> replies_;  // under mutex_
  int invalid_replies_ = 0;               // under mutex_
  test_support::ArrivalLog arrivals_;
};

TEST_F(CommandsTest, EveryAuthenticatedCommandIsAnsweredAndNoOtherOne) {
  ASSERT_NO_FATAL_FAILURE(StartServer());
  const int64_t method = Command(command_t::SET_METHOD, "newton");
  const int64_t bogus = Command(command_t::SET_METHOD, "bogus");
  const int64_t outside = Command(command_t::LOAD_SCENE, "../zeeman");
  const int64_t load = Command(command_t::LOAD_SCENE, "zeeman");  // answered when loaded
  const int64_t missing = Command(command_t::LOAD_SCENE, "nothere");

  const auto expect = [&](int64_t seq, int8_t command, bool ok, const std::string& text) {
    const std::optional<command_reply_t> r = ReplyTo(seq);
    ASSERT_TRUE(r.has_value()) << "no reply to " << text;
    EXPECT_EQ(r->command, command) << text;
    EXPECT_EQ(r->ok, ok ? 1 : 0) << r->message;
    EXPECT_EQ(r->epoch, server_->epoch());
    EXPECT_NE(r->message.find(text), std::string::npos) << r->message;
  };
  expect(method, command_t::SET_METHOD, true, "now newton");
  expect(bogus, command_t::SET_METHOD, false, "unknown method 'bogus'");
  expect(outside, command_t::LOAD_SCENE, false, "keeping scene 'curve2d_snap'");
  expect(load, command_t::LOAD_SCENE, true, "now scene 'zeeman'");
  expect(missing, command_t::LOAD_SCENE, false, "nothere");
  // After the load: the RESET goes back to the start of the new scene.
  // Refused and not answered: an operator of another session, and the session's device
  // (only an operator sends commands).
  const auth::KeySet other = testing::OperatorKeys(auth::SessionKey::Generate());
  const int64_t forged = Command(command_t::RESET, "", &other);
  const int64_t by_device = Command(command_t::RESET, "", &device_);
  const int64_t reset = Command(command_t::RESET, "");
  expect(reset, command_t::RESET, true, "start of scene 'zeeman'");
  EXPECT_FALSE(ReplyTo(forged, 0.5).has_value());
  EXPECT_FALSE(ReplyTo(by_device, 0.1).has_value());
  const std::string refusals = server_->Stats().refusals;
  EXPECT_NE(refusals.find("operator/unknown-key=1"), std::string::npos) << refusals;
  EXPECT_NE(refusals.find("device/wrong-role=1"), std::string::npos) << refusals;
  std::lock_guard<std::mutex> lock(mutex_);
  EXPECT_EQ(replies_.size(), 6u);
  EXPECT_EQ(invalid_replies_, 0);
  for (size_t i = 1; i < replies_.size(); ++i) EXPECT_GT(replies_[i].seq, replies_[i - 1].seq);
}

TEST_F(CommandsTest, EveryWayOutOfTheSceneDirIsRefusedAndCounted) {
  // The directory's traps: symlinks out (a file, a device), a FIFO, a 2 MiB file, a
  // directory, and a symlink that stays inside (also refused: regular files only).
  ASSERT_EQ(::symlink("/etc/passwd", (dir() + "/passwd.yaml").c_str()), 0);
  ASSERT_EQ(::symlink("/dev/zero", (dir() + "/zero.yaml").c_str()), 0);
  ASSERT_EQ(::symlink((dir() + "/zeeman.yaml").c_str(), (dir() + "/inside.yaml").c_str()), 0);
  ASSERT_EQ(::mkfifo((dir() + "/fifo.yaml").c_str(), 0600), 0);
  {
    std::ofstream big(dir() + "/big.yaml");
    big << "name: big\n#" << std::string(2 << 20, 'x') << "\n";
  }
  ASSERT_EQ(::mkdir((dir() + "/folder.yaml").c_str(), 0700), 0);
  StartServer();
  const std::string scene = server_->Stats().scene;

  struct Case {
    std::string argument;
    std::string expect;  // in the refusal message
  };
  const std::vector<Case> cases = {
      {"/etc/passwd", "path separator"},
      {"/dev/zero", "path separator"},
      {"../scenes/x", "path separator"},
      {"..", "'..'"},
      {"", "empty scene name"},
      {".hidden", "start with '.'"},
      {"a b", "characters other than"},
      {"passwd", "resolves outside"},
      {"zero.yaml", "resolves outside"},
      {"inside", "symbolic link"},
      {"fifo", "a FIFO, not a regular file"},
      {"big", "over the 1 MiB limit"},
      {"folder", "a directory, not a regular file"},
      {"no_such_scene", "no scene no_such_scene.yaml"},
  };
  const size_t models_before = Models();
  int64_t refused = 0;
  for (const Case& c : cases) {
    Command(command_t::LOAD_SCENE, c.argument);
    ASSERT_TRUE(WaitRefused(++refused)) << c.argument;
    const ServerStats s = server_->Stats();
    EXPECT_NE(s.last_command_message.find(c.expect), std::string::npos)
        << c.argument << ": " << s.last_command_message;
    EXPECT_NE(s.last_command_message.find("keeping scene '" + scene + "'"), std::string::npos)
        << s.last_command_message;
    EXPECT_EQ(s.rejected_messages, refused) << c.argument;
    EXPECT_EQ(s.scene, scene);
  }
  EXPECT_EQ(server_->Stats().commands_applied, 0);
  // The server kept answering through all of it and after.
  EXPECT_TRUE(test_support::WaitUntil([&] { return Models() > models_before + 20; }, kWaitS, 0.002));
  EXPECT_LT(MaxGapSince(models_before), 0.5);

  // A good name loads, with or without .yaml.
  Command(command_t::LOAD_SCENE, "zeeman");
  ASSERT_TRUE(WaitApplied(1));
  EXPECT_EQ(server_->Stats().scene, LoadScene(ScenePath("zeeman.yaml")).name);
  CopyScene("curve2d_snap.yaml");
  Command(command_t::LOAD_SCENE, "curve2d_snap.yaml");
  ASSERT_TRUE(WaitApplied(2));
  EXPECT_EQ(server_->Stats().scene, scene);
  EXPECT_EQ(server_->Stats().rejected_messages, refused);
}

TEST_F(CommandsTest, ForceModelsKeepFlowingDuringASlowLoad) {
  std::atomic<bool> in_load{false};
  ServerTestHooks hooks;
  hooks.before_load = [&] {
    in_load = true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  };
  StartServer({}, std::move(hooks));
  const std::string method = server_->Stats().method;
  const size_t from = Models();
  Command(command_t::LOAD_SCENE, "zeeman");
  ASSERT_TRUE(test_support::WaitUntil([&] { return in_load.load(); }, kWaitS, 0.002));
  // While it loads: another load and a method switch are refused, the scene stays.
  Command(command_t::LOAD_SCENE, "zeeman");
  ASSERT_TRUE(WaitRefused(1));
  EXPECT_NE(server_->Stats().last_command_message.find("still in progress"), std::string::npos);
  Command(command_t::SET_METHOD, "newton");
  ASSERT_TRUE(WaitRefused(2));
  EXPECT_NE(server_->Stats().last_command_message.find("in progress"), std::string::npos);
  EXPECT_EQ(server_->Stats().method, method);
  EXPECT_EQ(server_->Stats().commands_applied, 0);
  const size_t during = Models();
  ASSERT_TRUE(WaitApplied(1));
  EXPECT_EQ(server_->Stats().scene, LoadScene(ScenePath("zeeman.yaml")).name);
  // Models flowed through the 1.5 s load: ~200 Hz poses, no gap of 0.5 s.
  EXPECT_GT(Models(), during + 50);
  EXPECT_LT(MaxGapSince(from), 0.5);
  EXPECT_EQ(server_->Stats().rejected_messages, 0);
}

TEST_F(CommandsTest, ALoadPastItsTimeLimitIsAbandonedAndReported) {
  std::atomic<int> loads{0};
  ServerTestHooks hooks;
  hooks.before_load = [&] {
    if (loads.fetch_add(1) == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  };
  ServerParams params;
  params.load_timeout_s = 0.3;
  StartServer(params, std::move(hooks));
  const std::string scene = server_->Stats().scene;
  const size_t from = Models();
  const auto t0 = Clock::now();
  Command(command_t::LOAD_SCENE, "zeeman");
  ASSERT_TRUE(WaitRefused(1));
  const double reported_s = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_LT(reported_s, 1.2) << "the time limit is 0.3 s";
  const ServerStats s = server_->Stats();
  EXPECT_NE(s.last_command_message.find("abandoned"), std::string::npos) << s.last_command_message;
  EXPECT_EQ(s.rejected_messages, 1);
  EXPECT_EQ(s.scene, scene);
  // The abandoned load ends later; its scene is not swapped in.
  std::this_thread::sleep_for(std::chrono::milliseconds(1700));
  EXPECT_EQ(server_->Stats().scene, scene);
  EXPECT_EQ(server_->Stats().commands_applied, 0);
  EXPECT_LT(MaxGapSince(from), 0.5);
  // Then a load within the limit succeeds.
  Command(command_t::LOAD_SCENE, "zeeman");
  ASSERT_TRUE(WaitApplied(1));
  EXPECT_EQ(server_->Stats().scene, LoadScene(ScenePath("zeeman.yaml")).name);
}

TEST_F(CommandsTest, AllowMethodsRefusesAMethodSwitch) {
  ServerParams params;
  params.allow_methods = {"newton"};
  StartServer(params);
  const std::string method = server_->Stats().method;
  ASSERT_NE(method, "newton-ls");
  Command(command_t::SET_METHOD, "newton-ls");
  ASSERT_TRUE(WaitRefused(1));
  ServerStats s = server_->Stats();
  EXPECT_EQ(s.method, method);
  EXPECT_EQ(s.rejected_messages, 1);
  EXPECT_NE(s.last_command_message.find("not in --allow-methods"), std::string::npos)
      << s.last_command_message;
  Command(command_t::SET_METHOD, "newton");
  ASSERT_TRUE(WaitApplied(1));
  EXPECT_EQ(server_->Stats().method, "newton");
}

TEST(ServerParamsTest, AllowMethodsAndLoadTimeoutAreChecked) {
  ServerParams params;
  params.scene_path = "x.yaml";
  std::string error;
  params.allow_methods = {"newton", "gradient-descent"};
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("--allow-methods: unknown method 'gradient-descent'"), std::string::npos) << error;
  params.allow_methods = {"newton"};
  params.method = "newton-ls";
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("--method: 'newton-ls' is not in --allow-methods"), std::string::npos) << error;
  params.method = "newton";
  EXPECT_TRUE(params.IsValid(&error)) << error;
  EXPECT_TRUE(params.IsMethodAllowed("newton"));
  EXPECT_FALSE(params.IsMethodAllowed("higher-order"));
  params.load_timeout_s = 0.0;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("--load-timeout"), std::string::npos) << error;
}

TEST(SceneDirTest, NamesBecomeYamlFilesAndPathsAreRefused) {
  EXPECT_EQ(SceneFileName("curve2d_snap"), "curve2d_snap.yaml");
  EXPECT_EQ(SceneFileName("curve2d_snap.yaml"), "curve2d_snap.yaml");
  for (const std::string bad : {"/etc/passwd", "../x", "a/b", "..", "", ".x", "a\\b", "x;y"}) {
    EXPECT_THROW(SceneFileName(bad), SceneNameError) << bad;
  }
  // The default directory is the project's scenes/, and its scenes load by name.
  std::string path;
  const std::string text = ReadSceneByName(DefaultSceneDir(), "curve2d_snap", &path);
  EXPECT_EQ(ParseScene(text, path).name, LoadScene(ScenePath("curve2d_snap.yaml")).name);
}

}  // namespace
}  // namespace snapthread::server
