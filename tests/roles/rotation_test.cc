// Issue 25 item 4, rotation on a running session: `snapthread-keygen --rotate` (the root
// key moves to FILE.previous, a new FILE), a new device credential from the new root,
// SIGHUP to the server, the new credential written over the device's file, SIGHUP to the
// device. Throughout, the device's verified statuses show models arriving at every status
// and no fade tick; after the server's --key-grace-s (3 s here) a device still tagging
// with the old root's credential is refused (device/grace-over).
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "auth/role_keys.h"
#include "forger.h"
#include "role_session.h"
#include "test_support.h"

namespace snapthread::roles_test {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

class RotationTest : public RoleSessionTest {};

TEST_F(RotationTest, RotationDuringALiveSessionCausesNoFade) {
  const std::string device_key = creds_->Issue(auth::Role::kDevice, "hand");
  // What a device that missed the rotation keeps tagging with.
  const auth::KeySet old_device = test_support::RoleCredentials::Load(device_key, auth::Role::kDevice);
  ASSERT_NO_FATAL_FAILURE(StartWatch());
  auto server = StartServer(creds_->root_path(), {"--key-grace-s", "3"});
  auto device = StartDevice(device_key, "hand");
  ASSERT_TRUE(WaitForModels("hand", 30)) << device->Out() << server->Out();
  const auto base = watch_->NextDevice("hand", 10);
  const auto base_status = watch_->NextStatus(10);
  ASSERT_TRUE(base && base_status);

  const test_support::ProcessResult rotated = Keygen({"--rotate"});
  ASSERT_EQ(rotated.exit_code, 0) << rotated.out << rotated.err;
  ASSERT_TRUE(std::filesystem::exists(creds_->root_path() + ".previous"));
  watch_->AddServerKey(auth::DeriveServerPublicKey(creds_->Root()));
  creds_->Issue(auth::Role::kDevice, "hand", "device-hand.new.cred");
  server->Signal(SIGHUP);
  const auto hup = Clock::now();
  std::this_thread::sleep_for(500ms);
  creds_->Issue(auth::Role::kDevice, "hand", "device-hand.cred", /*overwrite=*/true);
  device->Signal(SIGHUP);
  // Ride past the grace and a little more.
  std::this_thread::sleep_until(hup + 4500ms);
  ASSERT_TRUE(server->running()) << "SIGHUP ended the server\n" << server->Out();
  ASSERT_TRUE(device->running()) << "SIGHUP ended the device\n" << device->Out();

  const std::vector<DeviceStatusView> history = watch_->device_history("hand");
  int after = 0;
  int64_t last = base->models_received;
  for (const DeviceStatusView& v : history) {
    if (v.at <= base->at) continue;
    ++after;
    EXPECT_GT(v.models_received, last) << "no model between two statuses (status " << after << ")";
    EXPECT_EQ(v.fades, base->fades) << "the device faded (status " << after << ")";
    EXPECT_EQ(v.models_rejected, base->models_rejected) << "the device refused a model (status " << after << ")";
    last = v.models_received;
  }
  EXPECT_GE(after, 5) << "too few verified device statuses across the rotation";
  const auto ridden = watch_->NextStatus(10);
  ASSERT_TRUE(ridden) << "no status verified by the old or the new server key";
  EXPECT_EQ(Refusals(ridden->refusals, "device"), Refusals(base_status->refusals, "device")) << ridden->refusals;

  // After the grace: the old root's credential is refused.
  // Poses only: models under the old device key are the device's own affair (its grace).
  Forger stale(session_, test_support::kLoopbackLcmUrl, &old_device,
               ForgerPlan{.models = false, .commands = false, .views = false});
  std::this_thread::sleep_for(300ms);  // the epoch, off the statuses
  stale.Start();
  std::this_thread::sleep_for(1500ms);
  stale.Stop();
  std::this_thread::sleep_for(300ms);
  const auto refused = watch_->NextStatus(10);
  ASSERT_TRUE(refused);
  EXPECT_GT(Refusals(refused->refusals, "device/grace-over"), 0) << refused->refusals;
  const auto still = watch_->NextDevice("hand", 10);
  ASSERT_TRUE(still);
  EXPECT_GT(still->models_received, last) << "the rotated device stopped getting models";
  EXPECT_EQ(still->fades, base->fades);
  EXPECT_TRUE(test_support::TerminateTogether({server.get(), device.get()}, 10.0));
}

}  // namespace
}  // namespace snapthread::roles_test
