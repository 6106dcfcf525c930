// Issue 25 item 6: for each kind of credential a forger may hold (an observer's, a device's
// of a grasp the scene lacks, a device's of another session's root, an operator's, none),
// the forger (forger.h) signs as well as it can poses for the device's grasp, force models
// for the device, commands, shapes and statuses. Against the genuine server on the root and
// the genuine device "hand":
//   * the server applies none of its poses or commands: with the device stopped (SIGSTOP)
//     so that only the forger speaks, the server's updates and dropped poses stay, its
//     scene and method stay, and its refusals grow by the claimed role;
//   * the device applies none of its models: with the server stopped, so that only the
//     forger answers the device's poses, models_received stays and models_rejected grows;
//   * an observer verifying with the server's public key (the test's own, and the web
//     bridge on an observer credential) accepts none of its shapes, solver statuses or
//     device statuses.
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "forger.h"
#include "environment.h"
#include "role_session.h"
#include "web_feed.h"
#include "test_support.h"

namespace snapthread::roles_test {
namespace {

using namespace std::chrono_literals;

enum class Holder { kObserver, kOtherDevice, kForeignDevice, kOperator, kNone };

std::string HolderName(const testing::TestParamInfo<Holder>& info) {
  switch (info.param) {
    case Holder::kObserver: return "Observer";
    case Holder::kOtherDevice: return "DeviceOfAnotherGrasp";
    case Holder::kForeignDevice: return "DeviceOfAnotherRoot";
    case Holder::kOperator: return "Operator";
    case Holder::kNone: return "NoCredential";
  }
  return "?";
}

constexpr auto kForgeFor = 1500ms;

class ForgerMatrixTest : public RoleSessionTest, public testing::WithParamInterface<Holder> {
 protected:
  // The forger's credential (nullopt: none), kept alive for the forger.
  std::optional<auth::KeySet> HolderKeys() {
    using auth::Role;
    switch (GetParam()) {
      case Holder::kObserver:
        return test_support::RoleCredentials::Load(creds_->Issue(Role::kObserver), Role::kObserver);
      case Holder::kOtherDevice:
        return test_support::RoleCredentials::Load(creds_->Issue(Role::kDevice, "other"), Role::kDevice);
      case Holder::kForeignDevice:
        return test_support::RoleCredentials::Load(foreign_.Issue(Role::kDevice, "hand"), Role::kDevice);
      case Holder::kOperator:
        return test_support::RoleCredentials::Load(creds_->Issue(Role::kOperator, "intruder"), Role::kOperator);
      case Holder::kNone:
        return std::nullopt;
    }
    return std::nullopt;
  }

  // Runs the forger for kForgeFor.
  static ForgerCounts Forge(Forger* forger) {
    const ForgerCounts before = forger->sent();
    forger->Start();
    std::this_thread::sleep_for(kForgeFor);
    forger->Stop();
    ForgerCounts after = forger->sent();
    after.poses -= before.poses;
    after.models -= before.models;
    after.commands -= before.commands;
    return after;
  }

  // Waits until the device's verified statuses show models arriving again.
  bool ModelsFlow(double timeout_s) {
    const auto first = watch_->NextDevice("hand", timeout_s);
    if (!first) return false;
    return test_support::WaitUntil(
        [&] {
          const auto d = watch_->device("hand");
          return d && d->models_received > first->models_received;
        },
        timeout_s, 0.05);
  }

  test_support::RoleCredentials foreign_{"roles_foreign"};
};

TEST_P(ForgerMatrixTest, NothingForgedIsAccepted) {
  const std::string device_key = creds_->Issue(auth::Role::kDevice, "hand");
  const std::optional<auth::KeySet> keys = HolderKeys();
  ASSERT_NO_FATAL_FAILURE(StartWatch());
  auto server = StartServer(creds_->root_path());
  auto device = StartDevice(device_key, "hand");
  ASSERT_TRUE(WaitForModels("hand", 30)) << device->Out() << server->Out();
#ifdef SNAPTHREAD_ROLES_TEST_WEB
  WebFeed web(bin_, creds_->Issue(auth::Role::kObserver, "", "web-observer.cred"), session_, dir());
  ASSERT_TRUE(web.ok()) << web.error();
#endif

  // The server, with only the forger speaking (it reads the epoch off the statuses).
  device->Signal(SIGSTOP);
  std::this_thread::sleep_for(300ms);
  Forger forger(session_, test_support::kLoopbackLcmUrl, keys ? &*keys : nullptr,
                ForgerPlan{.commands = GetParam() != Holder::kOperator});
  const auto s0 = watch_->NextStatus(10);
  ASSERT_TRUE(s0);
  const ForgerCounts sent = Forge(&forger);
  std::this_thread::sleep_for(300ms);
  const auto s1 = watch_->NextStatus(10);
  device->Signal(SIGCONT);
  ASSERT_TRUE(s1);
  ASSERT_GT(sent.poses, 100);
  EXPECT_EQ(s1->updates, s0->updates) << "the server solved a forged pose";
  EXPECT_EQ(s1->dropped_poses, s0->dropped_poses);
  EXPECT_EQ(s1->scene, s0->scene);
  EXPECT_EQ(s1->method, s0->method);
  const int64_t refused = TotalRefusals(s1->refusals) - TotalRefusals(s0->refusals);
  EXPECT_GE(refused, (sent.poses + sent.commands) / 2) << s0->refusals << " -> " << s1->refusals;
  // By the role each forgery claimed and why: its own role where it may not speak
  // (wrong-role), another grasp (wrong-grasp), a key no root of this session gives
  // (unknown-key: another root's, none, or its own key under a name it is not).
  auto grew = [&](const std::string& key) { return Refusals(s1->refusals, key) > Refusals(s0->refusals, key); };
  EXPECT_TRUE(grew("device")) << s1->refusals;  // its poses in the name of "hand"
  switch (GetParam()) {
    case Holder::kObserver:
      EXPECT_TRUE(grew("observer/wrong-role")) << s1->refusals;
      break;
    case Holder::kOperator:
      EXPECT_TRUE(grew("operator/wrong-role")) << s1->refusals;
      EXPECT_TRUE(grew("device/unknown-key")) << s1->refusals;
      break;
    case Holder::kOtherDevice:
      EXPECT_TRUE(grew("device/wrong-grasp")) << s1->refusals;
      EXPECT_TRUE(grew("device/wrong-role")) << s1->refusals;  // its commands
      EXPECT_TRUE(grew("device/unknown-key")) << s1->refusals;
      break;
    case Holder::kForeignDevice:
      EXPECT_TRUE(grew("device/unknown-key")) << s1->refusals;
      EXPECT_TRUE(grew("device/wrong-role")) << s1->refusals;
      break;
    case Holder::kNone:
      EXPECT_TRUE(grew("device/unknown-key")) << s1->refusals;
      EXPECT_TRUE(grew("operator/unknown-key")) << s1->refusals;
      break;
  }

  // The device, with only the forger answering its poses.
  ASSERT_TRUE(ModelsFlow(20)) << device->Out();
  server->Signal(SIGSTOP);
  std::this_thread::sleep_for(300ms);
  const auto d0 = watch_->NextDevice("hand", 10);
  ASSERT_TRUE(d0);
  const int64_t heard = forger.poses_heard();
  const ForgerCounts models = Forge(&forger);
  const auto d1 = watch_->NextDevice("hand", 10);
  server->Signal(SIGCONT);
  ASSERT_TRUE(d1);
  EXPECT_GT(forger.poses_heard(), heard + 100) << "the forger heard no poses to answer";
  ASSERT_GT(models.models, 100);
  EXPECT_EQ(d1->models_received, d0->models_received) << "the device took a forged model";
  EXPECT_GT(d1->models_rejected, d0->models_rejected) << "the device did not see the forged models";
  // Once the last genuine model is stale (the device's timeout and fade, scaled for a slow
  // build), only forged models remain: none may make a force.
  const auto stale = std::chrono::milliseconds(static_cast<int>(400 * test_support::SpeedScale()) + 100);
  if (d1->at - d0->at > stale) {
    EXPECT_EQ(d1->force_norm_n, 0.0) << "a force with only forged models";
  }

  // What an observer accepted: no forgery, while it heard them and the genuine ones.
  EXPECT_GT(watch_->shapes().forged_heard, 10);
  EXPECT_EQ(watch_->shapes().forged_verified, 0);
  EXPECT_GT(watch_->statuses().forged_heard, 10);
  EXPECT_EQ(watch_->statuses().forged_verified, 0);
  EXPECT_GT(watch_->device_statuses().forged_heard, 10);
  EXPECT_EQ(watch_->device_statuses().forged_verified, 0);
  EXPECT_GT(watch_->statuses().verified, 5);
#ifdef SNAPTHREAD_ROLES_TEST_WEB
  // The web bridge passed on the genuine shapes and nothing forged.
  EXPECT_GT(web.shapes(), 5) << web.process().Err();
  EXPECT_EQ(web.forged(), 0) << web.process().Err();
#endif
  std::printf("forger %s: sent %lld poses, %lld commands, %lld models; server refusals \"%s\" -> \"%s\"; "
              "device models_rejected %lld -> %lld\n",
              HolderName({GetParam(), 0}).c_str(), static_cast<long long>(sent.poses),
              static_cast<long long>(sent.commands), static_cast<long long>(models.models), s0->refusals.c_str(),
              s1->refusals.c_str(), static_cast<long long>(d0->models_rejected),
              static_cast<long long>(d1->models_rejected));
  // The session goes on.
  EXPECT_TRUE(ModelsFlow(20)) << device->Out();
#ifdef SNAPTHREAD_ROLES_TEST_WEB
  EXPECT_TRUE(test_support::TerminateTogether({server.get(), device.get(), &web.process()}, 10.0));
#else
  EXPECT_TRUE(test_support::TerminateTogether({server.get(), device.get()}, 10.0));
#endif
}

INSTANTIATE_TEST_SUITE_P(Holders, ForgerMatrixTest,
                         testing::Values(Holder::kObserver, Holder::kOtherDevice, Holder::kForeignDevice,
                                         Holder::kOperator, Holder::kNone),
                         HolderName);

}  // namespace
}  // namespace snapthread::roles_test
