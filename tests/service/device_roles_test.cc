// The device client on roles (docs/security.md, "Roles on the wire"), in one thread with
// a fake clock: force models are applied only when the server MACed them with this
// device's own key and addressed them to it; its statuses carry a certificate an observer
// accepts and the device's own signature; a reload keeps the previous key for its grace.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "allocation_counter.h"
#include "auth/device_certificate.h"
#include "auth/freshness_filter.h"
#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/role.h"
#include "auth/session_epoch.h"
#include "auth/session_key.h"
#include "device_client.h"
#include "device_fakes.h"
#include "device_keys.h"
#include "messages/channels.h"
#include "scripted_path.h"
#include "sim_path_device.h"

namespace snapthread::device {
namespace {

using testing::DeviceKeysFor;
using testing::Encoded;
using testing::ForceModelTagger;
using testing::InMemoryTransport;
using testing::SpringServer;

int64_t g_now_us = 0;
int64_t FakeClock() { return g_now_us; }

constexpr int64_t kGraceUs = 1000000;

// A device on device "hand"'s keys (issued from root_) and a spring server answering it.
struct Rig {
  Rig() : Rig(DeviceKeysFor(auth::SessionKey::Generate(), "hand", kGraceUs)) {}
  explicit Rig(std::unique_ptr<DeviceKeys> device_keys) : keys(std::move(device_keys)) {
    g_now_us = 1000000;
    EXPECT_TRUE(device.Open(nullptr));
    config.device_id = "roles-test";
    config.loop.realtime = false;
    config.log_period_us = 0;
    config.clock = &FakeClock;
    config.keys = keys.get();
    client = std::make_unique<DeviceClient>(&device, &wire, config);
    server.SignWith(keys->current().root(), auth::NewEpoch(), config.session, "hand");
    server.DeliverStatus();  // the device learns the epoch before the first model
    client->Receive(0);
  }
  // n servo ticks, each pose answered by the server (statuses at 50 Hz).
  void Run(int n) {
    for (int i = 0; i < n; ++i) {
      g_now_us += 1000;
      client->Tick(g_now_us, 0);
      client->Service(g_now_us);
      if (ticks_++ % 20 == 0) server.DeliverStatus();
      answered += server.AnswerAll();
      client->Receive(0);
    }
  }
  const ModelReceiver& rx() const { return client->receiver(); }

  std::unique_ptr<DeviceKeys> keys;
  SimPathDevice device{ScriptedPath({{-0.01, 0.0, 0.0}, {0.01, 0.005, 0.0}}, 0.02), &FakeClock};
  InMemoryTransport wire;
  SpringServer server{&wire, 40.0};
  DeviceClientConfig config;
  std::unique_ptr<DeviceClient> client;
  int answered = 0;
  int ticks_ = 0;
};

// The forgeries: each answers every pose; none may be applied, each must be counted.
TEST(DeviceRolesTest, ForceModelsNotMacedForThisDeviceByTheServerAreRefused) {
  const auth::SessionKey other_root = auth::SessionKey::Generate();
  struct Forgery {
    const char* what;
    bool counted_as_sender;  // else a bad MAC
  };
  for (const Forgery& f : {Forgery{"another device's key", false}, Forgery{"server signature only", false},
                           Forgery{"addressed to another device", true}, Forgery{"from an observer", true},
                           Forgery{"another session's key for this device", false}}) {
    SCOPED_TRACE(f.what);
    Rig rig;
    rig.Run(300);  // genuine: learned the epoch, models applied
    const uint64_t applied = rig.rx().received();
    ASSERT_GT(applied, 200u);
    ASSERT_EQ(rig.rx().rejected(), 0u);
    const auth::SessionKey& root = *rig.keys->current().root();
    const auth::KeySet other = auth::KeySet::ForRole(root, auth::Role::kDevice, "left");
    const auth::KeySet server = auth::KeySet::ForRole(root, auth::Role::kServer);
    const auth::KeySet observer = auth::KeySet::ForRole(root, auth::Role::kObserver);
    const auth::KeySet foreign = auth::KeySet::ForRole(other_root, auth::Role::kDevice, "hand");
    auth::Tagger t = ForceModelTagger(rig.keys->current());
    const std::string what = f.what;
    if (what == "another device's key") {
      t.mac_key = other.mac_key();
      t.key_id = other.tagger().key_id;
    } else if (what == "server signature only") {
      t = server.tagger();
      t.name = "hand";
    } else if (what == "addressed to another device") {
      t = ForceModelTagger(other);  // a genuine model for device "left", same grasp field
    } else if (what == "from an observer") {
      t = observer.tagger();
      t.name = "hand";
    } else {
      t = ForceModelTagger(foreign);
    }
    rig.server.TagModelsWith(t);
    const int before = rig.answered;
    rig.Run(300);
    const uint64_t forged = static_cast<uint64_t>(rig.answered - before);
    ASSERT_GT(forged, 200u);
    EXPECT_EQ(rig.rx().received(), applied);
    EXPECT_EQ(rig.rx().rejected(), forged);
    EXPECT_EQ(rig.rx().auth_rejected(), forged);
    EXPECT_EQ(rig.rx().sender_rejected(), f.counted_as_sender ? forged : 0u);
    EXPECT_EQ(rig.rx().model_filter().rejected(auth::Reason::kBadMac), f.counted_as_sender ? 0u : forged);
    EXPECT_EQ(rig.rx().other_grasp(), 0u);
    // The device faded: nothing it trusts is fresh.
    EXPECT_GT(rig.client->safety().counters().fade_ticks.load(), 0u);
  }
}

// Another hand's models (another device, another grasp) are passed over, not refused.
TEST(DeviceRolesTest, AnotherHandsModelsArePassedOverNotRejected) {
  Rig rig;
  rig.Run(100);
  const uint64_t applied = rig.rx().received();
  const auth::KeySet left =
      auth::KeySet::ForRole(*rig.keys->current().root(), auth::Role::kDevice, "left");
  rig.server.TagModelsWith(ForceModelTagger(left));
  int sent = 0;
  for (int i = 0; i < 50; ++i) {
    g_now_us += 1000;
    rig.client->Tick(g_now_us, 0);
    rig.client->Service(g_now_us);
    for (const device_state_t& pose : rig.server.TakeNewPoses()) {
      force_model_t m = rig.server.ModelFor(pose);
      m.grasp = "left";
      ASSERT_TRUE(rig.server.Send(m));
      ++sent;
    }
    rig.client->Receive(0);
  }
  ASSERT_GT(sent, 40);
  EXPECT_EQ(rig.rx().received(), applied);
  EXPECT_EQ(rig.rx().rejected(), 0u);
  EXPECT_EQ(rig.rx().other_grasp(), static_cast<uint64_t>(sent));
}

TEST(DeviceRolesTest, PosesAreMacedAndStatusesCertifiedAndSignedWithTheDeviceKey) {
  Rig rig;
  rig.Run(1200);  // > 2 status periods
  const messages::Channels channels(rig.config.session);
  const auth::KeySet& keys = rig.keys->current();
  const auth::SessionKey& root = *keys.root();
  const auth::PublicKey server_pk = auth::KeySet::ForRole(root, auth::Role::kServer).server_public_key();
  ASSERT_FALSE(rig.wire.states.empty());
  const device_state_t& pose = rig.wire.states.back();
  EXPECT_EQ(pose.sender_role, static_cast<int8_t>(auth::Role::kDevice));
  EXPECT_EQ(pose.sender_name, "hand");
  EXPECT_EQ(pose.key_id, auth::KeyIdToWire(keys.tagger().key_id));
  std::vector<uint8_t> pose_bytes = Encoded(pose);
  EXPECT_TRUE(auth::VerifyMac(pose_bytes.data(), pose_bytes.size(), channels.device_state, *keys.mac_key()));
  ASSERT_GE(rig.wire.statuses.size(), 2u);
  for (const device_status_t& st : rig.wire.statuses) {
    auth::PublicKey device_pk{};
    std::copy(std::begin(st.device_public_key), std::end(st.device_public_key), device_pk.begin());
    EXPECT_TRUE(auth::VerifyDeviceCertificate(server_pk, st.sender_name, st.key_expires, device_pk,
                                              st.device_certificate));
    const std::vector<uint8_t> bytes = Encoded(st);
    EXPECT_TRUE(auth::VerifySignature(bytes.data(), bytes.size(), channels.device_status, device_pk));
    EXPECT_TRUE(auth::VerifyMac(bytes.data(), bytes.size(), channels.device_status, *keys.mac_key()));
    // Any other device's key is not certified for this name.
    const auth::KeySet left = auth::KeySet::ForRole(root, auth::Role::kDevice, "left");
    EXPECT_FALSE(auth::VerifyDeviceCertificate(server_pk, st.sender_name, st.key_expires, *left.device_public_key(),
                                               st.device_certificate));
  }
  // A changed byte breaks the signature.
  std::vector<uint8_t> bytes = Encoded(rig.wire.statuses.back());
  bytes[10] ^= 1;
  auth::PublicKey device_pk{};
  std::copy(std::begin(rig.wire.statuses.back().device_public_key), std::end(rig.wire.statuses.back().device_public_key),
            device_pk.begin());
  EXPECT_FALSE(auth::VerifySignature(bytes.data(), bytes.size(), channels.device_status, device_pk));
}

// A rotation: the device reloads a new credential; the server still MACs under the old key
// (models in flight, or it reloads later): applied within the grace, refused after it.
TEST(DeviceRolesTest, AfterAReloadThePreviousKeyIsAcceptedForItsGraceOnly) {
  Rig rig;
  rig.Run(300);
  const uint64_t before = rig.rx().received();
  ASSERT_GT(before, 200u);
  const auth::SessionKey new_root = auth::SessionKey::Generate();
  std::string error;
  ASSERT_TRUE(rig.keys->Replace(auth::KeySet::ForRole(new_root, auth::Role::kDevice, "hand"), g_now_us, &error))
      << error;
  const int64_t new_id = auth::KeyIdToWire(rig.keys->current().tagger().key_id);
  // Within the grace (1 s): the old key's models are still applied, with no fade.
  const uint64_t fades = rig.client->safety().counters().fade_ticks.load();
  rig.Run(500);
  EXPECT_EQ(rig.wire.states.back().key_id, new_id);  // poses: the new key from the next one
  EXPECT_GT(rig.rx().received(), before + 450);
  EXPECT_EQ(rig.rx().rejected(), 0u);
  EXPECT_EQ(rig.client->safety().counters().fade_ticks.load(), fades);
  // After the grace: refused.
  rig.Run(600);
  const uint64_t at_end_of_grace = rig.rx().received();
  rig.Run(300);
  EXPECT_EQ(rig.rx().received(), at_end_of_grace);
  EXPECT_GE(rig.rx().model_filter().rejected(auth::Reason::kBadMac), 300u);
  // The server's new key for the device: applied again.
  rig.server.MacWith(auth::KeySet::ForRole(new_root, auth::Role::kDevice, "hand"));
  rig.Run(300);
  EXPECT_GT(rig.rx().received(), at_end_of_grace + 250);
}

// The io thread's tags (a pose at up to 1 kHz, a status) and the receive thread's MAC
// check allocate nothing once warm, with the key swapped by a reload in between.
TEST(DeviceRolesTest, TaggingAndCheckingAllocateNothingInSteadyState) {
  const auth::SessionKey root = auth::SessionKey::Generate();
  DeviceKeys keys(auth::KeySet::ForRole(root, auth::Role::kDevice, "hand"), kGraceUs);
  const messages::Channels channels(messages::kDefaultSession);
  device_state_t pose{};
  pose.device_id = "virtual-hand";
  device_status_t st{};
  st.device_id = "virtual-hand";
  force_model_t model{};
  const auth::Tagger model_tagger = ForceModelTagger(keys.current());
  ASSERT_TRUE(auth::Sign(&model, channels.force_model, 7, 1, model_tagger));
  const std::vector<uint8_t> model_bytes = Encoded(model);
  std::string error;
  long allocations = 0;
  for (int round = 0; round < 2; ++round) {
    // Warm-up of each size (the per-thread buffer), then counted.
    ASSERT_TRUE(auth::Sign(&pose, channels.device_state, 7, 1, keys.current().tagger()));
    ASSERT_TRUE(auth::Sign(&st, channels.device_status, 7, 2, *keys.current().device_status_tagger()));
    test_support::AllocationCounter counter;
    for (int64_t i = 0; i < 1000; ++i) {
      pose.seq = i;
      if (!auth::Sign(&pose, channels.device_state, 7, 10 + i, keys.current().tagger())) ADD_FAILURE();
      const auth::KeySet* k = keys.ForKeyId(model.key_id, 0);
      if (k == nullptr ||
          !auth::VerifyMac(model_bytes.data(), model_bytes.size(), channels.force_model, *k->mac_key())) {
        ADD_FAILURE();
      }
    }
    if (!auth::Sign(&st, channels.device_status, 7, 5000, *keys.current().device_status_tagger())) ADD_FAILURE();
    allocations += counter.mallocs();
    counter.Stop();
    // A reload between the rounds: the previous key still checks the model.
    if (round == 0) {
      ASSERT_TRUE(keys.Replace(auth::KeySet::ForRole(auth::SessionKey::Generate(), auth::Role::kDevice, "hand"), 0,
                               &error));
    }
  }
  EXPECT_EQ(allocations, 0);
}

TEST(DeviceRolesTest, AReloadOfAnotherDevicesCredentialIsRefused) {
  const auth::SessionKey root = auth::SessionKey::Generate();
  DeviceKeys keys(auth::KeySet::ForRole(root, auth::Role::kDevice, "hand"), kGraceUs);
  const int64_t id = auth::KeyIdToWire(keys.current().tagger().key_id);
  std::string error;
  EXPECT_FALSE(keys.Replace(auth::KeySet::ForRole(root, auth::Role::kDevice, "left"), 0, &error));
  EXPECT_NE(error.find("left"), std::string::npos) << error;
  EXPECT_FALSE(keys.Replace(auth::KeySet::ForRole(root, auth::Role::kObserver), 0, &error));
  EXPECT_EQ(auth::KeyIdToWire(keys.current().tagger().key_id), id);
  EXPECT_EQ(keys.reloads(), 0);
  EXPECT_EQ(keys.Previous(0), nullptr);
}

}  // namespace
}  // namespace snapthread::device
