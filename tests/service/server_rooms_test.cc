// The server's rooms on their own, without threads: the inbound gate (decode, MAC,
// freshness per device, kMaxDevices, the command queue, every refusal counted), the
// publisher (signed with the epoch and a rising auth_seq; a refused publish counted), and
// the LCM transport over memq:// (the session's channels, nothing else).
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "auth/message_mac.h"
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
#include "server_probe.h"
#include "server_stats.h"

namespace snapthread::server {
namespace {

using server_test_support::MakePose;
using test_support::Encode;

constexpr int64_t kEpoch = 0x1234;

class GateTest : public ::testing::Test {
 protected:
  // A pose of `device` signed with `key` for `epoch`.
  std::vector<uint8_t> Pose(const std::string& device, int64_t seq, int64_t epoch,
                            const auth::SessionKey& key, int64_t auth_seq) {
    device_state_t s = MakePose(seq, Eigen::Vector3d(0.01, 0.0, 0.0));
    s.device_id = device;
    EXPECT_TRUE(auth::Sign(&s, channels_.device_state, epoch, auth_seq, key));
    return Encode(s);
  }
  std::vector<uint8_t> Command(int64_t epoch, int64_t auth_seq) {
    command_t c = test_support::MakeCommand(command_t::RESET, "");
    EXPECT_TRUE(auth::Sign(&c, channels_.command, epoch, auth_seq, key_));
    return Encode(c);
  }
  void GiveDeviceState(const std::vector<uint8_t>& bytes) { gate_.OnDeviceState(bytes.data(), bytes.size()); }
  void GiveCommand(const std::vector<uint8_t>& bytes) { gate_.OnCommand(bytes.data(), bytes.size()); }
  ServerInbox::Taken Take() {
    return inbox_.Wait(ServerInbox::Clock::now());
  }

  messages::Channels channels_{"GATE"};
  auth::SessionKey key_ = auth::SessionKey::Generate();
  ServerInbox inbox_;
  ServerCounters counters_;
  InboundGate gate_{channels_, key_, kEpoch, &inbox_, &counters_};
};

TEST_F(GateTest, OnlyAuthenticFreshPosesReachTheInbox) {
  GiveDeviceState(Pose("a", 1, kEpoch, key_, 10));
  EXPECT_EQ(counters_.poses_received.load(), 1);
  // Refused: another key, another epoch, a replay, a lower auth_seq, garbage, a pose
  // signed for the command channel.
  GiveDeviceState(Pose("a", 2, kEpoch, auth::SessionKey::Generate(), 11));
  GiveDeviceState(Pose("a", 3, kEpoch + 1, key_, 12));
  GiveDeviceState(Pose("a", 1, kEpoch, key_, 10));
  GiveDeviceState(Pose("a", 4, kEpoch, key_, 9));
  GiveDeviceState({1, 2, 3});
  {
    device_state_t s = MakePose(5, Eigen::Vector3d::Zero());
    ASSERT_TRUE(auth::Sign(&s, channels_.command, kEpoch, 13, key_));
    GiveDeviceState(Encode(s));
  }
  EXPECT_EQ(counters_.rejected_messages.load(), 6);
  EXPECT_EQ(counters_.poses_received.load(), 1);
  // Each device has its own sequence: b may start low.
  GiveDeviceState(Pose("b", 6, kEpoch, key_, 1));
  EXPECT_EQ(counters_.poses_received.load(), 2);
  const ServerInbox::Taken taken = Take();
  ASSERT_EQ(taken.poses.size(), 1u);  // one grasp (""): the newest pose wins
  EXPECT_EQ(taken.poses[0].state.device_id, "b");
  EXPECT_GT(taken.poses[0].receive_utime, 0);
  EXPECT_EQ(counters_.dropped_poses.load(), 1);
}

TEST_F(GateTest, AtMostKMaxDevicesAreTracked) {
  for (size_t i = 0; i < InboundGate::kMaxDevices; ++i) {
    std::string id = "d";
    id += std::to_string(i);  // (GCC 12 warns wrongly about "d" + std::to_string(i))
    GiveDeviceState(Pose(id, 1, kEpoch, key_, 1));
  }
  EXPECT_EQ(counters_.poses_received.load(), static_cast<int64_t>(InboundGate::kMaxDevices));
  EXPECT_EQ(counters_.rejected_messages.load(), 0);
  GiveDeviceState(Pose("one too many", 1, kEpoch, key_, 1));
  EXPECT_EQ(counters_.rejected_messages.load(), 1);
  // A known device goes on; a forged pose of a new id never takes a slot.
  GiveDeviceState(Pose("d0", 2, kEpoch, key_, 2));
  EXPECT_EQ(counters_.poses_received.load(), static_cast<int64_t>(InboundGate::kMaxDevices) + 1);
}

TEST_F(GateTest, CommandsNeedTheEpochAndAPlaceInTheQueue) {
  GiveCommand(Command(kEpoch + 1, 1));  // another start's
  GiveCommand(Command(kEpoch, 1));
  GiveCommand(Command(kEpoch, 1));  // replayed
  EXPECT_EQ(counters_.rejected_messages.load(), 2);
  EXPECT_EQ(Take().commands.size(), 1u);
  for (size_t i = 0; i < ServerInbox::kMaxPendingCommands + 3; ++i) {
    GiveCommand(Command(kEpoch, 2 + static_cast<int64_t>(i)));
  }
  EXPECT_EQ(counters_.commands_refused.load(), 3);
  EXPECT_EQ(Take().commands.size(), ServerInbox::kMaxPendingCommands);
  EXPECT_EQ(counters_.rejected_messages.load(), 2);
}

TEST(PublisherTest, SignsEveryMessageAndCountsRefusals) {
  const messages::Channels channels("PUB");
  const auth::SessionKey key = auth::SessionKey::Generate();
  testing::MemoryServerTransport transport;
  std::vector<std::vector<uint8_t>> models, shapes;
  transport.AddListener([&](testing::Outbound channel, const std::vector<uint8_t>& bytes) {
    if (channel == testing::Outbound::kForceModel) models.push_back(bytes);
    if (channel == testing::Outbound::kShape) shapes.push_back(bytes);
  });
  ServerCounters counters;
  Publisher publisher(&transport, channels, key, kEpoch, &counters);
  force_model_t m{};
  m.grasp = "";
  EXPECT_TRUE(publisher.ForceModel(&m));
  const int64_t first_seq = m.auth_seq;
  EXPECT_TRUE(publisher.ForceModel(&m));
  EXPECT_GT(m.auth_seq, first_seq);
  EXPECT_EQ(m.epoch, kEpoch);
  thread_shape_t shape{};
  EXPECT_TRUE(publisher.Shape(&shape));
  ASSERT_EQ(models.size(), 2u);
  ASSERT_EQ(shapes.size(), 1u);
  // Signed for its own channel, with the session key.
  EXPECT_TRUE(auth::VerifyEncoded(models[0].data(), models[0].size(), channels.force_model, key));
  EXPECT_FALSE(auth::VerifyEncoded(models[0].data(), models[0].size(), channels.shape, key));
  EXPECT_TRUE(auth::VerifyEncoded(shapes[0].data(), shapes[0].size(), channels.shape, key));
  EXPECT_EQ(counters.shapes_published.load(), 1);
  EXPECT_EQ(counters.publish_failures.load(), 0);
  transport.RefusePublishing(true);
  solver_status_t status{};
  EXPECT_FALSE(publisher.SolverStatus(&status));
  EXPECT_FALSE(publisher.ForceModel(&m));
  EXPECT_EQ(counters.publish_failures.load(), 2);
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
