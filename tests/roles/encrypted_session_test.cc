// Issue 25 item 5 on real processes over udpm on loopback: a session whose senders run with
// --encrypt (the server on the root key, the device on its credential, snapthread-ctl on an
// operator's). A sniffer on the group (this test's raw LCM subscriber, holding nothing)
// sees only sealed_t envelopes: no pose, force, scene name or grasp name in any byte. The
// credential holders see the session as in clear: the device is answered without a fade,
// the operator loads a scene, the test's observer and the web bridge (observer credential)
// verify shapes and statuses, and snapthread-logger's log is read by snapthread-report with
// an observer credential and refused, message by message, without one.
#include <algorithm>
#include <chrono>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "auth/role_keys.h"
#include "auth/sealed_message.h"
#include "lcm_thread.h"
#include "role_session.h"
#include "test_support.h"
#include "web_feed.h"

namespace snapthread::roles_test {
namespace {

using test_support::ChildProcess;
using test_support::ProcessResult;

// Everything on the session's channels, as bytes on the wire (liblcm's plain-function
// subscription: no opening).
class Sniffer {
 public:
  Sniffer(const std::string& session) : lcm_(test_support::kLoopbackLcmUrl) {
    lcm_.lcm().subscribeFunction(session + "_.*", &Sniffer::On, this);
    lcm_.Start();
  }
  ~Sniffer() { lcm_.Stop(); }

  struct Seen {
    int64_t messages = 0, sealed = 0;
    std::set<std::string> channels;
    std::vector<std::string> leaks;  // "<channel>: <word>" for every word found in clear
  };
  Seen seen() {
    std::lock_guard<std::mutex> lock(mutex_);
    return seen_;
  }

 private:
  static void On(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Sniffer* self) {
    const auto* p = static_cast<const char*>(rbuf->data);
    const std::string bytes(p, p + rbuf->data_size);
    std::lock_guard<std::mutex> lock(self->mutex_);
    ++self->seen_.messages;
    if (auth::IsSealed(rbuf->data, rbuf->data_size)) ++self->seen_.sealed;
    self->seen_.channels.insert(channel);
    // Scene names, the grasp and device names, the method: all in clear in an unsealed session.
    for (const char* word : {"curve2d", "zeeman", "hand", "sim-path", "newton", "higher-order"}) {
      if (bytes.find(word) != std::string::npos) self->seen_.leaks.push_back(channel + ": " + word);
    }
  }

  test_support::LcmThread lcm_;
  std::mutex mutex_;
  Seen seen_;
};

class EncryptedSessionTest : public RoleSessionTest {
 protected:
  void TearDown() override {
    RoleSessionTest::TearDown();
    auth::ClearSealing();
  }
};

// "channel <name> ... messages N ... rejected R" of summary.txt, as (messages, rejected).
std::pair<int64_t, int64_t> ChannelLine(const std::string& summary, const std::string& channel) {
  std::istringstream in(summary);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("channel " + channel + " ", 0) != 0) continue;
    auto number_after = [&](const std::string& word) -> int64_t {
      const auto at = line.find(" " + word + " ");
      return at == std::string::npos ? -1 : std::stoll(line.substr(at + word.size() + 2));
    };
    return {number_after("messages"), number_after("rejected")};
  }
  return {-1, -1};
}

TEST_F(EncryptedSessionTest, ASnifferSeesOnlyEnvelopesAndCredentialHoldersTheWholeSession) {
  const std::string device_key = creds_->Issue(auth::Role::kDevice, "hand");
  const std::string observer_key = creds_->Issue(auth::Role::kObserver);
  const std::string operator_key = creds_->Issue(auth::Role::kOperator, "console");
  // This process holds the session's read key as an observer does: the watch opens envelopes.
  auth::SetSealing(auth::DeriveReadKey(creds_->Root()), nullptr, /*seal_outgoing=*/false);
  ASSERT_NO_FATAL_FAILURE(StartWatch());
  Sniffer sniffer(session_);
  const std::string log_path = dir() + "/sealed.lcmlog";
  ChildProcess logger({bin_ + "/snapthread-logger", "-q", "-c", session_ + "_.*", "--lcm-url",
                       test_support::kLoopbackLcmUrl, log_path},
                      test_support::OneLog(dir() + "/logger.log", true));
  ASSERT_TRUE(logger.started());
  auto server = StartServer(creds_->root_path(), {"--encrypt"});
  auto device = StartDevice(device_key, "hand", {"--encrypt"});
#ifdef SNAPTHREAD_ROLES_TEST_WEB
  WebFeed web(bin_, observer_key, session_, dir());
  ASSERT_TRUE(web.ok()) << web.error();
#endif

  ASSERT_TRUE(WaitForModels("hand", 30)) << device->Out() << server->Out();
  const auto before = watch_->NextDevice("hand", 10);
  ASSERT_TRUE(before);
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const auto after = watch_->NextDevice("hand", 10);
  ASSERT_TRUE(after);
  EXPECT_GT(after->models_received, before->models_received + 20) << device->Out();
  EXPECT_EQ(after->fades, before->fades) << device->Out();
  EXPECT_EQ(after->models_rejected, before->models_rejected) << device->Out();

  ProcessResult r = Ctl(operator_key, {"--encrypt", "--timeout-s", "30", "load-scene", "zeeman"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(test_support::WaitUntil(
      [&] {
        const auto s = watch_->status();
        return s && s->scene == "zeeman";
      },
      15));
#ifdef SNAPTHREAD_ROLES_TEST_WEB
  EXPECT_TRUE(test_support::WaitUntil([&] { return web.last_scene() == "zeeman"; }, 15))
      << web.shapes() << " shapes\n" << web.process().Err();
#endif
  EXPECT_GT(watch_->shapes().verified, 5);
  EXPECT_EQ(watch_->shapes().refused, 0);

  const Sniffer::Seen seen = sniffer.seen();
  EXPECT_GT(seen.messages, 1000);  // 2 s of the 1 kHz pose / model pair at least
  EXPECT_EQ(seen.sealed, seen.messages) << "a message left in clear";
  EXPECT_TRUE(seen.leaks.empty()) << seen.leaks.size() << " leaks, first: " << seen.leaks.front();
  for (const char* suffix : {"_DEVICE_STATE", "_FORCE_MODEL", "_SHAPE", "_SOLVER_STATUS", "_DEVICE_STATUS",
                             "_COMMAND", "_COMMAND_REPLY"}) {
    EXPECT_EQ(seen.channels.count(session_ + suffix), 1u) << suffix << " never heard";
  }

#ifdef SNAPTHREAD_ROLES_TEST_WEB
  EXPECT_TRUE(test_support::TerminateTogether({server.get(), device.get(), &web.process()}, 10.0));
#else
  EXPECT_TRUE(test_support::TerminateTogether({server.get(), device.get()}, 10.0));
#endif
  EXPECT_TRUE(test_support::TerminateTogether({&logger}, 10.0));

  // The review: with an observer credential every force model of the log decodes; without
  // one each is refused as sealed.
  r = Run("snapthread-report", {log_path, "--no-plots", "--session", session_, "--key", observer_key,
                                "--out", dir() + "/with_key"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const auto [models, rejected] =
      ChannelLine(test_support::ReadFile(dir() + "/with_key/summary.txt"), session_ + "_FORCE_MODEL");
  EXPECT_GT(models, 1000);
  EXPECT_EQ(rejected, 0);
  r = Run("snapthread-report", {log_path, "--no-plots", "--session", session_, "--out", dir() + "/without_key"});
  const std::string without = test_support::ReadFile(dir() + "/without_key/summary.txt");
  const auto [models_seen, refused] = ChannelLine(without, session_ + "_FORCE_MODEL");
  EXPECT_EQ(refused, models_seen) << without;
  EXPECT_NE(without.find("sealed"), std::string::npos) << without;
}

}  // namespace
}  // namespace snapthread::roles_test
