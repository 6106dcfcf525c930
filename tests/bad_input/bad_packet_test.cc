// Issue 12 item 6, packets: bad messages thrown at a live snapthread-server and a live
// snapthread-device over udpm on loopback. One row per case; each must be refused within
// 2 s, counted (rejected_messages in solver_status_t, models_rejected in device_status_t)
// and named in the process's log (within another second: the logs are rate-limited to a
// line a second), and the process must keep running. A case's packet is sent again every
// 150 ms until the log names it.
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "command_message.h"
#include "messages/channels.h"
#include "messages/subscribe.h"
#include "messages/validate.h"
#include "test_support.h"

namespace snapthread::bad_input {
namespace {

using Bytes = std::vector<uint8_t>;
using Clock = std::chrono::steady_clock;
constexpr double kLimitS = 2.0;
constexpr double kResendS = 0.15;
constexpr double kLogIntervalS = 1.0;  // the processes' rate limit on repeated warnings

template <class T>
Bytes Encode(const T& msg) {
  Bytes b(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// A copy of `msg` tagged by `tagger`, encoded.
template <class T>
Bytes Signed(T msg, const std::string& channel, int64_t epoch, auth::AuthSequence* seq,
             const auth::Tagger& tagger) {
  EXPECT_TRUE(auth::Sign(&msg, channel, epoch, seq->Next(), tagger));
  return Encode(msg);
}

// How the server tags force models for `device`: a MAC under the device's key, claiming
// the server's role and naming the device.
auth::Tagger ForceModelTagger(const auth::KeySet& device) { return device.ForceModelTagger(); }

Bytes Truncated(Bytes b) {
  b.resize(b.size() / 2);
  return b;
}
Bytes Trailing(Bytes b) {
  b.resize(b.size() + 1000, 0xAB);
  return b;
}
Bytes WrongFingerprint(Bytes b) {
  for (int i = 0; i < 8; ++i) b[static_cast<size_t>(i)] ^= 0x5A;
  return b;
}
Bytes BadMac(Bytes b) {
  b.back() ^= 0x01;  // the MAC is the last field
  return b;
}
Bytes Garbage(size_t size) {
  Bytes b(size);
  for (size_t i = 0; i < size; ++i) b[i] = static_cast<uint8_t>(i * 131 + 7);
  return b;
}
// A string length field (at `offset`) of 2^31 - 1.
Bytes HugeLength(Bytes b, size_t offset) {
  const uint8_t huge[4] = {0x7f, 0xff, 0xff, 0xff};
  std::memcpy(&b[offset], huge, 4);
  return b;
}

struct PacketCase {
  std::string name;
  std::string channel;
  std::function<Bytes()> packet;  // made once per case, sent until refused
  std::string expect;             // in the process's log
  bool counted = true;            // false: a command refused with a reply, not a bad message
};

// A process under test, its status counter (read from its status channel) and its log.
class LiveProcess {
 public:
  LiveProcess(const std::vector<std::string>& argv, const std::string& log, const std::string& status_channel)
      : log_(log), child_(argv, test_support::OneLog(log, true)), lcm_(test_support::kLoopbackLcmUrl) {
    messages::Subscribe<&LiveProcess::OnStatus>(lcm_, status_channel, this);
    thread_ = std::thread([this] {
      while (!stop_.load()) lcm_.handleTimeout(20);
    });
  }
  ~LiveProcess() { StopListening(); }
  void StopListening() {
    stop_.store(true);
    if (thread_.joinable()) thread_.join();
  }
  lcm::LCM& lcm() { return lcm_; }
  test_support::ChildProcess& child() { return child_; }
  int64_t count() const { return count_.load(); }
  int64_t epoch() const { return epoch_.load(); }
  std::string Log() const { return test_support::ReadFile(log_); }
  // Hooks for what a status carries: the counter and the sender's epoch.
  std::function<bool(const lcm::ReceiveBuffer*, int64_t* count, int64_t* epoch)> read_status;

  // Sends the case's packet, again every kResendS until the log names the reason (the
  // logs are rate-limited), and waits for the counter to rise (unless the case is not
  // counted). *counted_s / *named_s: when each was seen, -1 if not by the deadline.
  void Probe(const PacketCase& c, double* counted_s, double* named_s) {
    const Bytes packet = c.packet();
    const int64_t before = count();
    const size_t log_before = Log().size();
    const auto t0 = Clock::now();
    auto next_send = t0;
    *counted_s = c.counted ? -1.0 : 0.0;
    *named_s = -1.0;
    while (true) {
      const double s = std::chrono::duration<double>(Clock::now() - t0).count();
      const std::string log = Log();
      if (*named_s < 0 && log.size() > log_before && log.find(c.expect, log_before) != std::string::npos) {
        *named_s = s;
      }
      if (*counted_s < 0 && count() > before) *counted_s = s;
      if ((*named_s >= 0 && *counted_s >= 0) || s > kLimitS + kLogIntervalS) return;
      if (*named_s < 0 && Clock::now() >= next_send) {
        lcm_.publish(c.channel, packet.data(), static_cast<unsigned>(packet.size()));
        next_send = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kResendS));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

 private:
  void OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    int64_t count = 0, epoch = 0;
    if (read_status && read_status(rbuf, &count, &epoch)) {
      count_.store(count);
      epoch_.store(epoch);
    }
  }

  std::string log_;
  test_support::ChildProcess child_;
  lcm::LCM lcm_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<int64_t> count_{-1};
  std::atomic<int64_t> epoch_{0};
};

void RunCases(LiveProcess* target, const std::vector<PacketCase>& cases, const std::string& who) {
  for (const PacketCase& c : cases) {
    double counted_s = -1.0, named_s = -1.0;
    target->Probe(c, &counted_s, &named_s);
    EXPECT_GE(counted_s, 0.0) << who << ": " << c.name << ": not counted (count " << target->count() << ")";
    EXPECT_LE(counted_s, kLimitS) << who << ": " << c.name;
    EXPECT_GE(named_s, 0.0) << who << ": " << c.name << ": '" << c.expect << "' not in the log";
    // The reason is logged at most once a second (a flood must not become a flood of
    // lines): a refusal just after another waits for the next line.
    EXPECT_LE(named_s, c.counted ? kLimitS + kLogIntervalS : kLimitS) << who << ": " << c.name;
    EXPECT_TRUE(target->child().running()) << who << " died at case " << c.name;
    std::printf("%s %-28s counted in %.2f s, named in the log in %.2f s\n", who.c_str(), c.name.c_str(),
                counted_s, named_s);
  }
}

device_state_t Pose(const std::string& device_id) {
  device_state_t p{};
  p.utime = 1;
  p.seq = 1;
  p.device_id = device_id;
  p.orientation[0] = 1.0;
  return p;
}

TEST(BadPacketTest, ALiveServerRefusesAndCountsEveryBadPoseAndCommand) {
  const test_support::SessionKeyFile key;
  const test_support::ScopedTempDir dir("bad_packets_server");
  const std::string scenes = dir.path() + "/scenes";
  std::filesystem::create_directory(scenes);
  std::filesystem::copy_file(test_support::ScenePath("zeeman.yaml"), scenes + "/zeeman.yaml");
  ASSERT_EQ(::mkfifo((scenes + "/fifo.yaml").c_str(), 0644), 0);
  std::ofstream(scenes + "/big.yaml") << std::string(2 << 20, '#');
  std::ofstream(scenes + "/deep.yaml") << "model: " << std::string(1000, '[') << '\n';
  std::filesystem::create_symlink("/etc/passwd", scenes + "/passwd.yaml");

  const std::string session = test_support::UniqueSession("BADPKT_S");
  const messages::Channels ch(session);
  LiveProcess server({test_support::BinDir() + "/snapthread-server", "--scene", scenes + "/zeeman.yaml",
                      "--scene-dir", scenes, "--session", session, "--lcm-url", test_support::kLoopbackLcmUrl,
                      "--status-rate-hz", "50", "--summary", dir.path() + "/summary.json"},
                     dir.path() + "/server.log", ch.solver_status);
  server.read_status = [](const lcm::ReceiveBuffer* rbuf, int64_t* count, int64_t* epoch) {
    solver_status_t st;
    if (!messages::DecodeAndValidate(rbuf->data, static_cast<int>(rbuf->data_size), &st, nullptr)) return false;
    *count = st.rejected_messages;
    *epoch = st.epoch;
    return true;
  };
  ASSERT_TRUE(test_support::WaitUntil([&] { return server.epoch() != 0; }, 10.0))
      << "no status from the server\n" << server.Log();
  const int64_t epoch = server.epoch();
  // The device of the scene's only grasp ("hand") and an operator, issued from the root key.
  const auth::KeySet device_keys = auth::KeySet::ForRole(key.key(), auth::Role::kDevice, "hand");
  const auth::KeySet operator_keys = auth::KeySet::ForRole(key.key(), auth::Role::kOperator, "operator");
  auth::AuthSequence seq;
  const auto pose = [&](device_state_t p, int64_t e) {
    return Signed(p, ch.device_state, e, &seq, device_keys.tagger());
  };
  const auto command = [&](int8_t what, const std::string& arg, int64_t e) {
    return Signed(test_support::MakeCommand(what, arg), ch.command, e, &seq, operator_keys.tagger());
  };
  const device_state_t good = Pose("badinput");
  device_state_t nan_pose = good;
  nan_pose.position[1] = std::numeric_limits<double>::quiet_NaN();
  device_state_t zero_quaternion = good;
  zero_quaternion.orientation[0] = 0.0;
  Bytes replayed;  // a genuine pose, sent once before its case replays it
  const int8_t kLoad = command_t::LOAD_SCENE;
  const std::vector<PacketCase> cases = {
      {"pose truncated", ch.device_state, [&] { return Truncated(pose(good, epoch)); }, "truncated"},
      {"pose + 1000 bytes", ch.device_state, [&] { return Trailing(pose(good, epoch)); }, "trailing bytes"},
      {"200 kB of garbage", ch.device_state, [] { return Garbage(200000); }, "fingerprint"},
      {"pose wrong fingerprint", ch.device_state, [&] { return WrongFingerprint(pose(good, epoch)); },
       "fingerprint"},
      {"pose NaN position", ch.device_state, [&] { return pose(nan_pose, epoch); }, "position"},
      {"pose zero quaternion", ch.device_state, [&] { return pose(zero_quaternion, epoch); }, "quaternion"},
      {"pose device_id 2 GB", ch.device_state, [&] { return HugeLength(pose(good, epoch), 24); }, "device_id"},
      {"pose bad MAC", ch.device_state, [&] { return BadMac(pose(good, epoch)); }, "bad-mac"},
      // No tag at all: the trailer's defaults claim the server's role, which sends no pose.
      {"pose unsigned", ch.device_state, [&] { return Encode(good); }, "wrong-role"},
      {"pose wrong epoch", ch.device_state, [&] { return pose(good, epoch ^ 0x5A5A); }, "foreign-epoch"},
      {"pose replayed", ch.device_state,
       [&] {
         replayed = pose(good, epoch);
         server.lcm().publish(ch.device_state, replayed.data(), static_cast<unsigned>(replayed.size()));
         std::this_thread::sleep_for(std::chrono::milliseconds(100));
         return replayed;
       },
       "replay"},
      {"command truncated", ch.command, [&] { return Truncated(command(kLoad, "zeeman", epoch)); }, "truncated"},
      {"command wrong fingerprint", ch.command, [&] { return WrongFingerprint(command(kLoad, "zeeman", epoch)); },
       "fingerprint"},
      {"command bad MAC", ch.command, [&] { return BadMac(command(kLoad, "zeeman", epoch)); }, "bad-mac"},
      {"command wrong epoch", ch.command, [&] { return command(kLoad, "zeeman", epoch + 1); }, "foreign-epoch"},
      {"LOAD_SCENE /etc/passwd", ch.command, [&] { return command(kLoad, "/etc/passwd", epoch); },
       "path separator"},
      {"LOAD_SCENE /dev/zero", ch.command, [&] { return command(kLoad, "/dev/zero", epoch); }, "path separator"},
      {"LOAD_SCENE ..", ch.command, [&] { return command(kLoad, "..", epoch); }, "'..'"},
      {"LOAD_SCENE a FIFO", ch.command, [&] { return command(kLoad, "fifo", epoch); }, "a FIFO"},
      {"LOAD_SCENE 2 MB", ch.command, [&] { return command(kLoad, "big", epoch); }, "1 MiB"},
      {"LOAD_SCENE symlink", ch.command, [&] { return command(kLoad, "passwd", epoch); }, "symbolic link"},
      {"LOAD_SCENE missing", ch.command, [&] { return command(kLoad, "nosuch", epoch); }, "no scene"},
      {"LOAD_SCENE deep nesting", ch.command, [&] { return command(kLoad, "deep", epoch); }, "nested deeper",
       false},
      {"SET_METHOD magic", ch.command, [&] { return command(command_t::SET_METHOD, "magic", epoch); },
       "unknown method", false},
  };
  RunCases(&server, cases, "server");
  server.StopListening();
  server.child().Signal(SIGTERM);
  int code = -1;
  EXPECT_TRUE(server.child().Wait(5.0, &code));
  EXPECT_EQ(code, 0) << server.Log();
  const std::string summary = test_support::ReadFile(dir.path() + "/summary.json");
  EXPECT_NE(summary.find("\"commands_applied\": 0"), std::string::npos) << summary;  // scene kept
  EXPECT_GE(cases.size(), 20u);
}

// The device's fake server: a signed status with its epoch every 50 ms, and an answer to
// every pose (kept, so a case can replay one; MAC'd under the key of device "hand", which
// the device given the root key acts as) until StopAnswering: from then on the cases'
// models are the only ones, tagged with model_seq() from the test's thread.
class FakeServer {
 public:
  FakeServer(const messages::Channels& ch, lcm::LCM* lcm, const auth::SessionKey& root)
      : ch_(ch),
        lcm_(lcm),
        server_(auth::KeySet::ForRole(root, auth::Role::kServer)),
        device_(auth::KeySet::ForRole(root, auth::Role::kDevice, "hand")),
        model_tagger_(ForceModelTagger(device_)),
        epoch_(auth::NewEpoch()) {
    messages::Subscribe<&FakeServer::OnPose>(lcm_, ch_.device_state, this);
  }
  void Tick() {
    if (Clock::now() < next_status_) return;
    next_status_ = Clock::now() + std::chrono::milliseconds(50);
    solver_status_t st{};
    st.scene = "fake";
    st.method = "fake";
    if (auth::Sign(&st, ch_.solver_status, epoch_, status_seq_.Next(), server_.tagger())) {
      lcm_->publish(ch_.solver_status, &st);
    }
  }
  int64_t epoch() const { return epoch_; }
  force_model_t LastAnswer() {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_;
  }
  Bytes LastAnswerBytes() {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_bytes_;
  }
  void StopAnswering() { answering_.store(false); }
  auth::AuthSequence* model_seq() { return &model_seq_auth_; }
  const auth::Tagger& model_tagger() const { return model_tagger_; }

 private:
  void OnPose(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    device_state_t pose;
    if (!answering_.load()) return;
    if (!messages::DecodeAndValidate(rbuf->data, static_cast<int>(rbuf->data_size), &pose, nullptr)) return;
    force_model_t m{};
    m.seq = ++model_seq_;
    m.device_seq = pose.seq;
    m.device_utime = pose.utime;
    for (int i = 0; i < 3; ++i) m.u0[i] = pose.position[i];
    if (!auth::Sign(&m, ch_.force_model, epoch_, model_seq_auth_.Next(), model_tagger_)) return;
    std::lock_guard<std::mutex> lock(mutex_);
    last_ = m;
    last_bytes_ = Encode(m);
    lcm_->publish(ch_.force_model, last_bytes_.data(), static_cast<unsigned>(last_bytes_.size()));
  }

  messages::Channels ch_;
  lcm::LCM* lcm_;
  const auth::KeySet server_;
  const auth::KeySet device_;
  const auth::Tagger model_tagger_;
  int64_t epoch_;
  auth::AuthSequence status_seq_;
  auth::AuthSequence model_seq_auth_;
  std::atomic<bool> answering_{true};
  int64_t model_seq_ = 0;
  Clock::time_point next_status_{};
  std::mutex mutex_;
  force_model_t last_{};
  Bytes last_bytes_;
};

TEST(BadPacketTest, ALiveDeviceRefusesAndCountsEveryBadForceModel) {
  const test_support::SessionKeyFile key;
  const test_support::ScopedTempDir dir("bad_packets_device");
  const std::string scene = dir.path() + "/scene.yaml";
  std::ofstream(scene) << "model: zeeman\ngrasp:\n  start: [0, 2.5]\n  path: [[-2, 3.0], [2, 1.5]]\n"
                          "device:\n  model_units_per_metre: 100\n  model_origin: [0, 2.5, 0]\n";
  const std::string session = test_support::UniqueSession("BADPKT_D");
  const messages::Channels ch(session);
  LiveProcess device({test_support::BinDir() + "/snapthread-device", "--backend", "sim-path", "--scene", scene,
                      "--session", session, "--lcm-url", test_support::kLoopbackLcmUrl, "--no-rt", "--duration",
                      "60", "--speed-m-per-s", "0.02"},
                     dir.path() + "/device.log", ch.device_status);
  device.read_status = [](const lcm::ReceiveBuffer* rbuf, int64_t* count, int64_t* epoch) {
    device_status_t st;
    if (!messages::DecodeAndValidate(rbuf->data, static_cast<int>(rbuf->data_size), &st, nullptr)) return false;
    *count = st.models_rejected;
    *epoch = st.epoch;
    return true;
  };
  // The fake server on its own LCM instance and thread.
  lcm::LCM server_lcm(test_support::kLoopbackLcmUrl);
  FakeServer server(ch, &server_lcm, key.key());
  std::atomic<bool> stop{false};
  std::thread server_thread([&] {
    while (!stop.load()) {
      server_lcm.handleTimeout(5);
      server.Tick();
    }
  });
  const int64_t epoch = server.epoch();
  // The device has learned the epoch and accepts models (its status is signed with it).
  const bool ready = test_support::WaitUntil([&] { return device.epoch() == epoch; }, 10.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  server.StopAnswering();
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const auto model = [&](force_model_t m, int64_t e) {
    return Signed(m, ch.force_model, e, server.model_seq(), server.model_tagger());
  };
  const auto answer = [&] { return server.LastAnswer(); };
  std::vector<PacketCase> cases = {
      {"model truncated", ch.force_model, [&] { return Truncated(model(answer(), epoch)); }, "truncated"},
      {"model + 1000 bytes", ch.force_model, [&] { return Trailing(model(answer(), epoch)); }, "trailing bytes"},
      {"model wrong fingerprint", ch.force_model, [&] { return WrongFingerprint(model(answer(), epoch)); },
       "fingerprint"},
      {"model NaN f0", ch.force_model,
       [&] {
         force_model_t m = answer();
         m.f0[0] = std::numeric_limits<double>::quiet_NaN();
         return model(m, epoch);
       },
       "f0"},
      {"200 kB of garbage", ch.force_model, [] { return Garbage(200000); }, "fingerprint"},
      {"model bad MAC", ch.force_model, [&] { return BadMac(model(answer(), epoch)); }, "bad MAC"},
      {"model unsigned", ch.force_model,
       [&] {
         force_model_t m = answer();
         std::memset(m.mac, 0, sizeof(m.mac));
         return Encode(m);
       },
       "bad MAC"},
      {"model wrong epoch", ch.force_model, [&] { return model(answer(), epoch ^ 0x5A5A); }, "foreign epoch"},
      {"model replayed", ch.force_model, [&] { return server.LastAnswerBytes(); }, "replayed"},
      {"model echoes no pose", ch.force_model,
       [&] {
         force_model_t m = answer();
         m.device_seq = -12345;
         return model(m, epoch);
       },
       "echoes no pose"},
  };
  if (ready) RunCases(&device, cases, "device");
  stop.store(true);
  server_thread.join();
  device.StopListening();
  EXPECT_TRUE(ready) << "the device never took the fake server's epoch\n" << device.Log();
  device.child().Signal(SIGTERM);
  int code = -1;
  EXPECT_TRUE(device.child().Wait(5.0, &code));
  EXPECT_EQ(code, 0) << device.Log();
}

}  // namespace
}  // namespace snapthread::bad_input
