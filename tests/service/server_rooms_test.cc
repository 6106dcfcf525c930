// The server's rooms on their own, without threads: the inbound gate (decode, role, key,
// MAC, grasp, freshness per sender, revocation and rotation by reload, kMaxSenders, the
// command queue, every refusal counted by role and reason), the publisher (server
// signatures, device MACs on force models, signed models at display rate, the epoch and
// a rising auth_seq; a refused publish counted), and
// the LCM transport over memq:// (the session's channels, nothing else).
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "auth/key_file.h"
#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/revocation_list.h"
#include "auth/session_epoch.h"
#include "auth/session_key.h"
#include "command_message.h"
#include "inbound_gate.h"
#include "lcm_server_transport.h"
#include "messages/channels.h"
#include "messages/subscribe.h"
#include "publisher.h"
#include "server_inbox.h"
#include "server_memory_transport.h"
#include "server_keys.h"
#include "server_probe.h"
#include "server_stats.h"
#include "session_key_file.h"

namespace snapthread::server {
namespace {

using server_test_support::MakePose;
using test_support::Encode;

constexpr int64_t kEpoch = 0x1234;

auth::SessionKey Copy(const auth::SessionKey& key) {
  return auth::SessionKey::FromBytes(key.data(), auth::SessionKey::kBytes);
}

class GateTest : public ::testing::Test {
 protected:
  // A pose for `grasp` tagged by `sender` for `epoch` (on `channel`, the pose channel by
  // default).
  std::vector<uint8_t> Pose(const auth::Tagger& sender, int64_t seq, int64_t auth_seq, const std::string& grasp = "",
                            int64_t epoch = kEpoch, const std::string* channel = nullptr) {
    device_state_t s = MakePose(seq, Eigen::Vector3d(0.01, 0.0, 0.0));
    s.grasp = grasp;
    return testing::Tagged(s, channel != nullptr ? *channel : channels_.device_state, epoch, auth_seq, sender);
  }
  std::vector<uint8_t> Command(int64_t epoch, int64_t auth_seq, const auth::Tagger* sender = nullptr) {
    return testing::Tagged(test_support::MakeCommand(command_t::RESET, ""), channels_.command, epoch, auth_seq,
                           sender != nullptr ? *sender : ops_.tagger());
  }
  void GiveDeviceState(const std::vector<uint8_t>& bytes) { gate_.OnDeviceState(bytes.data(), bytes.size()); }
  void GiveCommand(const std::vector<uint8_t>& bytes) { gate_.OnCommand(bytes.data(), bytes.size()); }
  ServerInbox::Taken Take() {
    return inbox_.Wait(ServerInbox::Clock::now());
  }
  int64_t Refused(auth::Role role, RefusalReason refusal) const {
    return counters_.refusals.Get(static_cast<int8_t>(role), refusal);
  }

  messages::Channels channels_{"GATE"};
  test_support::SessionKeyFile key_file_;  // the root key; FILE.revoked beside it
  const auth::SessionKey& root_ = key_file_.key();
  const auth::KeySet hand_ = testing::DeviceKeys(root_, "hand");
  const auth::KeySet ops_ = testing::OperatorKeys(root_, "ops");
  ServerKeys keys_{key_file_.path(), Copy(root_), 60.0};
  ServerInbox inbox_;
  ServerCounters counters_;
  InboundGate gate_{channels_, &keys_, kEpoch, &inbox_, &counters_};
};

TEST_F(GateTest, OnlyAuthenticFreshPosesReachTheInbox) {
  GiveDeviceState(Pose(hand_.tagger(), 1, 10));
  EXPECT_EQ(counters_.poses_received.load(), 1);
  // Refused: the device of another session, another epoch, a replay, a lower auth_seq,
  // garbage, a pose tagged for the command channel.
  const auth::KeySet stranger = testing::DeviceKeys(auth::SessionKey::Generate(), "hand");
  GiveDeviceState(Pose(stranger.tagger(), 2, 11));
  GiveDeviceState(Pose(hand_.tagger(), 3, 12, "", kEpoch + 1));
  GiveDeviceState(Pose(hand_.tagger(), 1, 10));
  GiveDeviceState(Pose(hand_.tagger(), 4, 9));
  GiveDeviceState({1, 2, 3});
  GiveDeviceState(Pose(hand_.tagger(), 5, 13, "", kEpoch, &channels_.command));
  EXPECT_EQ(counters_.rejected_messages.load(), 6);
  EXPECT_EQ(counters_.poses_received.load(), 1);
  EXPECT_EQ(counters_.refusals.Format(),
            "device/unknown-key=1 device/bad-mac=1 device/foreign-epoch=1 device/replay=2 unknown/malformed=1");
  // Each device has its own sequence: "b" may start low; its pose takes its own slot.
  const auth::KeySet b = testing::DeviceKeys(root_, "b");
  GiveDeviceState(Pose(b.tagger(), 6, 1, "b"));
  GiveDeviceState(Pose(hand_.tagger(), 7, 14));
  EXPECT_EQ(counters_.poses_received.load(), 3);
  const ServerInbox::Taken taken = Take();
  ASSERT_EQ(taken.poses.size(), 2u);  // the newest pose of each (grasp, device)
  EXPECT_EQ(taken.poses[0].state.seq, 7);
  EXPECT_EQ(taken.poses[1].state.sender_name, "b");
  EXPECT_GT(taken.poses[0].receive_utime, 0);
  // Each carries the key it was made with (the force model answering it is MACed with it).
  ASSERT_NE(taken.poses[0].key, nullptr);
  EXPECT_EQ(taken.poses[0].key->name, "hand");
  EXPECT_EQ(0, std::memcmp(taken.poses[0].key->key.data(), hand_.mac_key()->data(), auth::SessionKey::kBytes));
  EXPECT_EQ(counters_.dropped_poses.load(), 1);
}

// Issue 25: for each role, a holder of its credential (and of another session's) tries the
// pose channel: 0 accepted, each refusal counted under the claimed role and its reason.
TEST_F(GateTest, OnlyTheGraspsOwnDeviceMovesIt) {
  const auth::KeySet observer = auth::KeySet::ForRole(root_, auth::Role::kObserver);
  const auth::KeySet left = testing::DeviceKeys(root_, "left");
  const auth::KeySet expired = testing::DeviceKeys(root_, "hand", UnixSeconds() - 10);
  const auth::KeySet other_root = testing::DeviceKeys(auth::SessionKey::Generate(), "right");
  auth::Tagger impostor = left.tagger();  // "left"'s key claiming to be "right"
  impostor.name = "right";
  int64_t seq = 0;
  const auto give = [&](const auth::Tagger& sender, const std::string& grasp) {
    ++seq;
    GiveDeviceState(Pose(sender, seq, seq, grasp));
  };
  give(ops_.tagger(), "right");
  give(observer.tagger(), "right");
  give(auth::RootMacTagger(root_), "right");  // the old single key, as the server
  give(left.tagger(), "right");
  give(impostor, "right");
  give(expired.tagger(), "");
  give(other_root.tagger(), "right");
  EXPECT_EQ(counters_.poses_received.load(), 0);
  EXPECT_TRUE(Take().poses.empty());
  EXPECT_EQ(Refused(auth::Role::kOperator, RefusalReason::kWrongRole), 1);
  EXPECT_EQ(Refused(auth::Role::kObserver, RefusalReason::kWrongRole), 1);
  EXPECT_EQ(Refused(auth::Role::kServer, RefusalReason::kWrongRole), 1);
  EXPECT_EQ(Refused(auth::Role::kDevice, RefusalReason::kWrongGrasp), 1);
  EXPECT_EQ(Refused(auth::Role::kDevice, RefusalReason::kUnknownKey), 2);
  EXPECT_EQ(Refused(auth::Role::kDevice, RefusalReason::kExpired), 1);
  EXPECT_EQ(counters_.rejected_messages.load(), 7);
  EXPECT_EQ(counters_.refusals.Total(), 7);
  // The genuine "right" device is unaffected.
  const auth::KeySet right = testing::DeviceKeys(root_, "right");
  GiveDeviceState(Pose(right.tagger(), ++seq, 1, "right"));
  EXPECT_EQ(counters_.poses_received.load(), 1);
}

TEST_F(GateTest, RevocationActsFromTheNextMessage) {
  GiveDeviceState(Pose(hand_.tagger(), 1, 1));
  EXPECT_EQ(counters_.poses_received.load(), 1);
  auth::RevocationList::Append(key_file_.path() + ".revoked", "device hand\n");
  keys_.Reload(UnixSeconds());
  GiveDeviceState(Pose(hand_.tagger(), 2, 2));
  EXPECT_EQ(counters_.poses_received.load(), 1);
  EXPECT_EQ(Refused(auth::Role::kDevice, RefusalReason::kRevoked), 1);
  // Another device goes on. A broken list keeps the old one (logged naming the file).
  const auth::KeySet left = testing::DeviceKeys(root_, "left");
  GiveDeviceState(Pose(left.tagger(), 3, 1, "left"));
  EXPECT_EQ(counters_.poses_received.load(), 2);
  {
    std::ofstream broken(key_file_.path() + ".revoked", std::ios::app);
    broken << "nonsense here\n";
  }
  keys_.Reload(UnixSeconds());
  GiveDeviceState(Pose(hand_.tagger(), 4, 3));
  EXPECT_EQ(Refused(auth::Role::kDevice, RefusalReason::kRevoked), 2);
  EXPECT_EQ(keys_.reloads(), 2);
}

TEST_F(GateTest, ThePreviousRootIsAcceptedOnlyDuringItsGrace) {
  auth::WriteNewKey(auth::KeyLocation{key_file_.path(), "test"}, /*overwrite=*/true);
  const auth::SessionKey new_root = auth::LoadKey(auth::KeyLocation{key_file_.path(), "test"});
  keys_.Reload(UnixSeconds());  // grace: 60 s from now
  const auth::KeySet new_hand = testing::DeviceKeys(new_root, "hand");
  GiveDeviceState(Pose(hand_.tagger(), 1, 1));
  GiveDeviceState(Pose(new_hand.tagger(), 2, 2));
  EXPECT_EQ(counters_.poses_received.load(), 2);
  // The server signs with both roots during the grace, with the new one only after it.
  const ServerSigners& signers = keys_.signers();
  EXPECT_EQ(signers.current.public_key(), new_hand.server_public_key());
  ASSERT_NE(signers.PreviousAt(UnixSeconds()), nullptr);
  EXPECT_EQ(signers.PreviousAt(UnixSeconds())->public_key(), hand_.server_public_key());
  EXPECT_EQ(signers.PreviousAt(UnixSeconds() + 61), nullptr);
  // A second rotation whose reload is stamped 61 s ago: its previous root's grace is over.
  auth::WriteNewKey(auth::KeyLocation{key_file_.path(), "test"}, /*overwrite=*/true);
  keys_.Reload(UnixSeconds() - 61);
  GiveDeviceState(Pose(new_hand.tagger(), 3, 3));
  GiveDeviceState(Pose(hand_.tagger(), 4, 4));  // two roots back: unknown
  EXPECT_EQ(counters_.poses_received.load(), 2);
  EXPECT_EQ(Refused(auth::Role::kDevice, RefusalReason::kGraceOver), 1);
  EXPECT_EQ(Refused(auth::Role::kDevice, RefusalReason::kUnknownKey), 1);
}

TEST_F(GateTest, AtMostKMaxSendersAreTracked) {
  std::vector<auth::KeySet> devices;
  for (size_t i = 0; i < InboundGate::kMaxSenders; ++i) {
    std::string name = "d";
    name += std::to_string(i);  // (GCC 12 warns wrongly about "d" + std::to_string(i))
    devices.push_back(testing::DeviceKeys(root_, name));
    GiveDeviceState(Pose(devices.back().tagger(), 1, 1, name));
  }
  EXPECT_EQ(counters_.poses_received.load(), static_cast<int64_t>(InboundGate::kMaxSenders));
  EXPECT_EQ(counters_.rejected_messages.load(), 0);
  const auth::KeySet extra = testing::DeviceKeys(root_, "one-too-many");
  GiveDeviceState(Pose(extra.tagger(), 1, 1, "one-too-many"));
  EXPECT_EQ(counters_.rejected_messages.load(), 1);
  EXPECT_EQ(Refused(auth::Role::kDevice, RefusalReason::kTooMany), 1);
  // A known device goes on; a forged pose of a new name never takes a slot.
  GiveDeviceState(Pose(devices[0].tagger(), 2, 2, "d0"));
  EXPECT_EQ(counters_.poses_received.load(), static_cast<int64_t>(InboundGate::kMaxSenders) + 1);
}

TEST_F(GateTest, CommandsNeedAnOperatorTheEpochAndAPlaceInTheQueue) {
  GiveCommand(Command(kEpoch + 1, 1));  // another start's
  GiveCommand(Command(kEpoch, 1));
  GiveCommand(Command(kEpoch, 1));  // replayed
  EXPECT_EQ(counters_.rejected_messages.load(), 2);
  EXPECT_EQ(Take().commands.size(), 1u);
  // Only an operator of this session commands: a device, an observer, another session's
  // operator are refused.
  const auth::KeySet observer = auth::KeySet::ForRole(root_, auth::Role::kObserver);
  const auth::KeySet stranger = testing::OperatorKeys(auth::SessionKey::Generate(), "ops");
  GiveCommand(Command(kEpoch, 2, &hand_.tagger()));
  GiveCommand(Command(kEpoch, 3, &observer.tagger()));
  GiveCommand(Command(kEpoch, 4, &stranger.tagger()));
  EXPECT_TRUE(Take().commands.empty());
  EXPECT_EQ(counters_.refusals.Format(),
            "device/wrong-role=1 observer/wrong-role=1 operator/unknown-key=1 operator/foreign-epoch=1 "
            "operator/replay=1");
  for (size_t i = 0; i < ServerInbox::kMaxPendingCommands + 3; ++i) {
    GiveCommand(Command(kEpoch, 2 + static_cast<int64_t>(i)));
  }
  EXPECT_EQ(counters_.commands_refused.load(), 3);
  EXPECT_EQ(Take().commands.size(), ServerInbox::kMaxPendingCommands);
  EXPECT_EQ(counters_.rejected_messages.load(), 5);
}

TEST(PublisherTest, TagsEveryMessageAndCountsRefusals) {
  const messages::Channels channels("PUB");
  test_support::SessionKeyFile key_file;
  ServerKeys keys(key_file.path(), Copy(key_file.key()), 60.0);
  const auth::KeySet hand = testing::DeviceKeys(key_file.key(), "hand");
  const auth::KeySet stranger = testing::DeviceKeys(auth::SessionKey::Generate(), "hand");
  const DeviceKey* device = keys.DeviceKeyFor("hand", hand.expires_unix_s(), hand.tagger().key_id, *hand.mac_key());
  ASSERT_NE(device, nullptr);
  testing::MemoryServerTransport transport;
  std::vector<std::vector<uint8_t>> models, shapes;
  transport.AddListener([&](testing::Outbound channel, const std::vector<uint8_t>& bytes) {
    if (channel == testing::Outbound::kForceModel) models.push_back(bytes);
    if (channel == testing::Outbound::kShape) shapes.push_back(bytes);
  });
  ServerCounters counters;
  Publisher publisher(&transport, channels, &keys, kEpoch, &counters);
  force_model_t m{};
  m.grasp = "";
  EXPECT_TRUE(publisher.ForceModel(&m, 0, device));
  const int64_t first_seq = m.auth_seq;
  EXPECT_TRUE(publisher.ForceModel(&m, 0, device));  // within 1/60 s: not signed
  EXPECT_GT(m.auth_seq, first_seq);
  EXPECT_EQ(m.epoch, kEpoch);
  EXPECT_EQ(m.sender_role, static_cast<int8_t>(auth::Role::kServer));
  EXPECT_EQ(m.sender_name, "hand");
  EXPECT_EQ(m.key_id, auth::KeyIdToWire(hand.tagger().key_id));
  thread_shape_t shape{};
  EXPECT_TRUE(publisher.Shape(&shape));
  ASSERT_EQ(models.size(), 2u);
  ASSERT_EQ(shapes.size(), 1u);
  // Models: the device's MAC, for their own channel; the first carries the server's
  // signature, the second (1/60 s later at most) none.
  const auth::PublicKey& server_pk = hand.server_public_key();
  EXPECT_TRUE(auth::VerifyMac(models[0].data(), models[0].size(), channels.force_model, *hand.mac_key()));
  EXPECT_TRUE(auth::VerifyMac(models[1].data(), models[1].size(), channels.force_model, *hand.mac_key()));
  EXPECT_FALSE(auth::VerifyMac(models[0].data(), models[0].size(), channels.shape, *hand.mac_key()));
  EXPECT_FALSE(auth::VerifyMac(models[0].data(), models[0].size(), channels.force_model, *stranger.mac_key()));
  EXPECT_TRUE(auth::VerifySignature(models[0].data(), models[0].size(), channels.force_model, server_pk));
  EXPECT_FALSE(auth::VerifySignature(models[1].data(), models[1].size(), channels.force_model, server_pk));
  // The shape: signed by the server (not by another session's), no MAC.
  EXPECT_TRUE(auth::VerifySignature(shapes[0].data(), shapes[0].size(), channels.shape, server_pk));
  EXPECT_FALSE(auth::VerifySignature(shapes[0].data(), shapes[0].size(), channels.shape,
                                     stranger.server_public_key()));
  EXPECT_FALSE(auth::VerifySignature(shapes[0].data(), shapes[0].size(), channels.force_model, server_pk));
  EXPECT_FALSE(auth::VerifyMac(shapes[0].data(), shapes[0].size(), channels.shape, *hand.mac_key()));
  EXPECT_EQ(counters.shapes_published.load(), 1);
  EXPECT_EQ(counters.publish_failures.load(), 0);
  transport.RefusePublishing(true);
  solver_status_t status{};
  EXPECT_FALSE(publisher.SolverStatus(&status));
  EXPECT_FALSE(publisher.ForceModel(&m, 0, device));
  EXPECT_FALSE(publisher.ForceModel(&m, 0, nullptr));  // no device key: never sent
  EXPECT_EQ(counters.publish_failures.load(), 3);
  EXPECT_EQ(counters.statuses_published.load(), 0);
}

// What an LcmServerTransport hands over, by channel.
struct RecordingSink final : InboundSink {
  void OnDeviceState(const void*, size_t size) override { states.push_back(size); }
  void OnCommand(const void*, size_t size) override { commands.push_back(size); }
  std::vector<size_t> states, commands;
};

struct ModelWatch {
  void On(const lcm::ReceiveBuffer*, const std::string& channel) { channels.push_back(channel); }
  std::vector<std::string> channels;
};

TEST(LcmServerTransportTest, CarriesTheSessionsChannelsOnly) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  const messages::Channels mine("MINE"), other("OTHER");
  LcmServerTransport transport(&lcm, mine.session);
  EXPECT_EQ(transport.Describe(), "(provided)");
  ModelWatch watch;
  lcm::Subscription* sub = messages::Subscribe<&ModelWatch::On>(lcm, ".*_FORCE_MODEL", &watch);
  const device_state_t pose = MakePose(1, Eigen::Vector3d::Zero());
  const command_t command = test_support::MakeCommand(command_t::RESET, "");
  ASSERT_EQ(lcm.publish(mine.device_state, &pose), 0);
  ASSERT_EQ(lcm.publish(other.device_state, &pose), 0);
  ASSERT_EQ(lcm.publish(mine.command, &command), 0);
  force_model_t model{};
  EXPECT_TRUE(transport.PublishForceModel(model));
  RecordingSink sink;
  for (int i = 0; i < 10; ++i) transport.Receive(0, &sink);
  ASSERT_EQ(sink.states.size(), 1u);
  EXPECT_EQ(sink.states[0], static_cast<size_t>(pose.getEncodedSize()));
  ASSERT_EQ(sink.commands.size(), 1u);
  EXPECT_EQ(sink.commands[0], static_cast<size_t>(command.getEncodedSize()));
  ASSERT_EQ(watch.channels.size(), 1u);
  EXPECT_EQ(watch.channels[0], mine.force_model);
  lcm.unsubscribe(sub);
}

}  // namespace
}  // namespace snapthread::server
