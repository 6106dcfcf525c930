// The roles through a whole server over an in-memory transport (server_memory_transport.h):
// force models MACed for their device and signed at display rate, a rotation on a
// running session (--key-grace-s), a revocation read by a reload. The gate's refusals one
// by one: server_rooms_test.cc.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "auth/key_file.h"
#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/revocation_list.h"
#include "auth/session_epoch.h"
#include "environment.h"
#include "server.h"
#include "server_keys.h"
#include "server_memory_transport.h"
#include "server_probe.h"
#include "session_key_file.h"

namespace snapthread::server {
namespace {

using server_test_support::MakePose;
using server_test_support::Probe;

bool WaitFor(const std::function<bool()>& pred) {
  return test_support::WaitUntil(pred, std::chrono::duration<double>(server_test_support::kWait).count(), 0.002);
}

class ServerRolesTest : public ::testing::Test {
 protected:
  // Keeps every force model as sent (its device_seq and bytes), then starts the server.
  void StartServer(const std::string& scene_file) {
    transport_.AddListener([this](testing::Outbound channel, const std::vector<uint8_t>& bytes) {
      force_model_t m;
      if (channel != testing::Outbound::kForceModel ||
          m.decode(bytes.data(), 0, static_cast<int>(bytes.size())) < 0) {
        return;
      }
      std::lock_guard<std::mutex> lock(raw_mutex_);
      raw_models_.emplace_back(m.device_seq, bytes);
    });
    ServerParams params;
    params.session = "ROLES";
    params.scene_path = test_support::ScenePath(scene_file);
    params.log_level = "warn";
    params.key_path = key_file_.path();
    params.key_grace_s = key_grace_s_;
    server_ = std::make_unique<Server>(params, &transport_);
    probe_ = std::make_unique<Probe>(&transport_);
    server_->Start();
  }
  void TearDown() override {
    if (server_) server_->Stop();
    probe_.reset();
    server_.reset();
  }
  // A pose tagged by `sender` (the device "hand" of the session by default).
  void Publish(const device_state_t& s, const auth::KeySet* sender = nullptr) {
    transport_.DeliverDeviceState(testing::Tagged(s, server_->channels().device_state, server_->epoch(),
                                                  auth_seq_.Next(), (sender ? *sender : device_).tagger()));
  }
  void PublishAs(const auth::KeySet& sender, const device_state_t& s) { Publish(s, &sender); }
  // The bytes of the model answering device_seq (empty when none was sent).
  std::vector<uint8_t> RawModel(int64_t device_seq) {
    std::lock_guard<std::mutex> lock(raw_mutex_);
    for (const auto& [seq, bytes] : raw_models_) {
      if (seq == device_seq) return bytes;
    }
    return {};
  }
  bool MacBy(const auth::KeySet& device, const std::vector<uint8_t>& bytes) {
    return auth::VerifyMac(bytes.data(), bytes.size(), server_->channels().force_model, *device.mac_key());
  }

  test_support::SessionKeyFile key_file_;
  const auth::KeySet device_ = testing::DeviceKeys(key_file_.key());
  auth::AuthSequence auth_seq_;
  double key_grace_s_ = 60.0;
  testing::MemoryServerTransport transport_;
  std::unique_ptr<Server> server_;
  std::unique_ptr<Probe> probe_;
  std::mutex raw_mutex_;
  std::vector<std::pair<int64_t, std::vector<uint8_t>>> raw_models_;
};

// Force models are MACed with the device's key (and no other); the server's signature
// rides on them at display rate only (>= 1/60 s apart), and verifies with this session's
// server key only.
TEST_F(ServerRolesTest, ForceModelsCarryTheDeviceMacAndSignaturesAtDisplayRate) {
  StartServer("curve2d_snap.yaml");
  const auth::KeySet stranger = testing::DeviceKeys(auth::SessionKey::Generate(), "hand");
  constexpr int kPoses = 150;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 1; i <= kPoses; ++i) {
    Publish(MakePose(i, Eigen::Vector3d(0.0005 * (i % 20), 0.0, 0.0)));
    force_model_t m;
    ASSERT_TRUE(probe_->WaitModel(i, &m));
  }
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string& channel = server_->channels().force_model;
  int signed_models = 0;
  for (int i = 1; i <= kPoses; ++i) {
    const std::vector<uint8_t> bytes = RawModel(i);
    ASSERT_FALSE(bytes.empty());
    EXPECT_TRUE(MacBy(device_, bytes));
    EXPECT_FALSE(MacBy(stranger, bytes));
    EXPECT_FALSE(auth::VerifySignature(bytes.data(), bytes.size(), channel, stranger.server_public_key()));
    if (auth::VerifySignature(bytes.data(), bytes.size(), channel, device_.server_public_key())) ++signed_models;
  }
  EXPECT_GE(signed_models, 1);
  EXPECT_LE(signed_models, static_cast<int>(elapsed_s * 60.0) + 2) << kPoses << " models in " << elapsed_s << " s";
}

// A rotation on a running session (a new root file, then a reload): a device still on the
// previous root is answered (its models MACed with its own key) for the grace period, and
// refused as grace-over after it; a device on the new root is answered throughout.
TEST_F(ServerRolesTest, ARotationKeepsOldDevicesForTheGraceOnly) {
  key_grace_s_ = 3.0;
  StartServer("curve2d_snap.yaml");
  Publish(MakePose(1, Eigen::Vector3d::Zero()));
  force_model_t m;
  ASSERT_TRUE(probe_->WaitModel(1, &m));
  const auth::KeyLocation where{key_file_.path(), "test"};
  auth::WriteNewKey(where, /*overwrite=*/true);
  const auth::KeySet new_hand = testing::DeviceKeys(auth::LoadKey(where), "hand");
  const int64_t reloaded_at = UnixSeconds();
  server_->RequestReload();
  ASSERT_TRUE(WaitFor([&] { return server_->key_reloads() == 1; }));
  Publish(MakePose(2, Eigen::Vector3d(0.001, 0.0, 0.0)));  // the previous root's device
  ASSERT_TRUE(probe_->WaitModel(2, &m));
  EXPECT_TRUE(MacBy(device_, RawModel(2)));
  PublishAs(new_hand, MakePose(3, Eigen::Vector3d(0.002, 0.0, 0.0)));
  ASSERT_TRUE(probe_->WaitModel(3, &m));
  EXPECT_TRUE(MacBy(new_hand, RawModel(3)));
  EXPECT_FALSE(MacBy(device_, RawModel(3)));
  // After the grace: refused, and reported in the solver status.
  ASSERT_TRUE(WaitFor([&] { return UnixSeconds() >= reloaded_at + 4; }));
  Publish(MakePose(4, Eigen::Vector3d(0.003, 0.0, 0.0)));
  ASSERT_TRUE(WaitFor([&] { return server_->Stats().refusals == "device/grace-over=1"; }))
      << server_->Stats().refusals;
  EXPECT_TRUE(probe_->WaitStatus(0, [](const solver_status_t& s) { return s.refusals == "device/grace-over=1"; }));
  EXPECT_TRUE(RawModel(4).empty());
  PublishAs(new_hand, MakePose(5, Eigen::Vector3d(0.004, 0.0, 0.0)));
  EXPECT_TRUE(probe_->WaitModel(5, &m));
}

// A revocation read by a reload while the session runs refuses the device from its next pose.
TEST_F(ServerRolesTest, ARevokedDeviceIsRefusedFromItsNextPose) {
  StartServer("curve2d_snap.yaml");
  Publish(MakePose(1, Eigen::Vector3d::Zero()));
  force_model_t m;
  ASSERT_TRUE(probe_->WaitModel(1, &m));
  auth::RevocationList::Append(key_file_.path() + ".revoked", "device hand\n");
  server_->RequestReload();
  ASSERT_TRUE(WaitFor([&] { return server_->key_reloads() == 1; }));
  Publish(MakePose(2, Eigen::Vector3d(0.001, 0.0, 0.0)));
  ASSERT_TRUE(WaitFor([&] { return server_->Stats().refusals == "device/revoked=1"; }))
      << server_->Stats().refusals;
  EXPECT_TRUE(probe_->WaitStatus(0, [](const solver_status_t& s) { return s.refusals == "device/revoked=1"; }));
  EXPECT_EQ(server_->Stats().updates, 1);
}

// Issue 25: holders of each other credential try to move the hand: 0 of their poses are
// answered, and the solver status reports each refusal under the claimed role and reason.
TEST_F(ServerRolesTest, NoOtherCredentialMovesTheHand) {
  StartServer("curve2d_snap.yaml");
  const auth::SessionKey& root = key_file_.key();
  const auth::KeySet ops = testing::OperatorKeys(root);
  const auth::KeySet observer = auth::KeySet::ForRole(root, auth::Role::kObserver);
  const auth::KeySet left = testing::DeviceKeys(root, "left");
  const auth::KeySet expired = testing::DeviceKeys(root, "hand", UnixSeconds() - 1);
  const auth::KeySet stranger = testing::DeviceKeys(auth::SessionKey::Generate(), "hand");
  int64_t seq = 0;
  for (const auth::KeySet* forger : {&ops, &observer, &left, &expired, &stranger}) {
    ++seq;
    PublishAs(*forger, MakePose(seq, Eigen::Vector3d(0.001 * static_cast<double>(seq), 0.0, 0.0)));
  }
  device_state_t for_right = MakePose(++seq, Eigen::Vector3d::Zero());
  for_right.grasp = "right";
  PublishAs(left, for_right);
  const std::string expected =
      "device/unknown-key=1 device/expired=1 device/wrong-grasp=2 observer/wrong-role=1 operator/wrong-role=1";
  EXPECT_TRUE(probe_->WaitStatus(0, [&](const solver_status_t& s) { return s.refusals == expected; }))
      << server_->Stats().refusals;
  EXPECT_EQ(server_->Stats().updates, 0);
  EXPECT_TRUE(probe_->models().empty());
  // The genuine device is answered.
  Publish(MakePose(++seq, Eigen::Vector3d::Zero()));
  force_model_t m;
  EXPECT_TRUE(probe_->WaitModel(seq, &m));
}

}  // namespace
}  // namespace snapthread::server
