// Sealed messages (--encrypt): an envelope opens only with the session's read key, on
// its own channel, unaltered; the message inside keeps its tags; a subscriber over a real
// liblcm (memq://) gets the message as if sent in clear, while a subscriber without the
// key, and anything reading the bytes on the wire, sees neither the scene name nor a pose.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/role_keys.h"
#include "auth/sealed_message.h"
#include "messages/publish.h"
#include "messages/subscribe.h"
#include "messages/validate.h"
#include "sample_messages.h"

namespace snapthread::auth {
namespace {

using Bytes = std::vector<uint8_t>;

Bytes Encode(const solver_status_t& msg) {
  Bytes b(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

Bytes ToBytes(ByteView v) { return Bytes(v.data, v.data + v.size); }

bool Contains(const Bytes& hay, const std::string& needle) {
  return std::search(hay.begin(), hay.end(), needle.begin(), needle.end()) != hay.end();
}

class SealedMessageTest : public ::testing::Test {
 protected:
  void TearDown() override { ClearSealing(); }
  SessionKey root_ = SessionKey::Generate();
  SessionKey other_root_ = SessionKey::Generate();
  KeySet server_ = KeySet::ForRole(root_, Role::kServer);
  solver_status_t status_ = test_support::Sample(static_cast<const solver_status_t*>(nullptr));
};

TEST_F(SealedMessageTest, AnEnvelopeHidesThePayloadAndOpensOnlyWithTheReadKeyOnItsChannel) {
  status_.scene = "secret_scene_name";
  ASSERT_TRUE(Sign(&status_, "S_SOLVER_STATUS", 7, 1, server_.tagger()));
  const Bytes plain = Encode(status_);
  ASSERT_TRUE(Contains(plain, "secret_scene_name"));

  SetSealing(server_.read_key(), nullptr, /*seal_outgoing=*/true);
  const Bytes sealed = ToBytes(SealForChannel(ByteView{plain.data(), plain.size()}, "S_SOLVER_STATUS"));
  ASSERT_FALSE(sealed.empty());
  EXPECT_TRUE(IsSealed(sealed.data(), sealed.size()));
  EXPECT_FALSE(IsSealed(plain.data(), plain.size()));
  EXPECT_FALSE(Contains(sealed, "secret_scene_name"));

  const auto opened = OpenSealed(sealed.data(), sealed.size(), "S_SOLVER_STATUS");
  ASSERT_TRUE(opened.has_value());
  EXPECT_EQ(ToBytes(*opened), plain);
  // The message inside keeps the server's signature.
  EXPECT_TRUE(VerifySignature(opened->data, opened->size, "S_SOLVER_STATUS", server_.server_public_key()));

  EXPECT_FALSE(OpenSealed(sealed.data(), sealed.size(), "S_SHAPE").has_value()) << "another channel";
  EXPECT_FALSE(OpenSealedWith(DeriveReadKey(other_root_), sealed.data(), sealed.size(), "S_SOLVER_STATUS"))
      << "another session's read key";
  EXPECT_TRUE(OpenSealedWith(server_.read_key(), sealed.data(), sealed.size(), "S_SOLVER_STATUS"));
  for (std::size_t i = 0; i < sealed.size(); i += 7) {
    Bytes bad = sealed;
    bad[i] ^= 0x20;
    EXPECT_FALSE(OpenSealed(bad.data(), bad.size(), "S_SOLVER_STATUS").has_value()) << "byte " << i;
  }
  Bytes longer = sealed;
  longer.push_back(0);
  EXPECT_FALSE(OpenSealed(longer.data(), longer.size(), "S_SOLVER_STATUS").has_value()) << "trailing byte";
}

TEST_F(SealedMessageTest, EveryCredentialOpensButNoneOfAnotherSession) {
  SetSealing(server_.read_key(), nullptr, true);
  ASSERT_TRUE(Sign(&status_, "S_SOLVER_STATUS", 7, 1, server_.tagger()));
  const Bytes plain = Encode(status_);
  const Bytes sealed = ToBytes(SealForChannel(ByteView{plain.data(), plain.size()}, "S_SOLVER_STATUS"));
  for (Role role : {Role::kDevice, Role::kObserver, Role::kOperator}) {
    const KeySet holder = KeySet::FromCredential(IssueCredential(root_, role, role == Role::kObserver ? "" : "n", 0));
    EXPECT_TRUE(OpenSealedWith(holder.read_key(), sealed.data(), sealed.size(), "S_SOLVER_STATUS"))
        << RoleToString(role);
    const KeySet stranger =
        KeySet::FromCredential(IssueCredential(other_root_, role, role == Role::kObserver ? "" : "n", 0));
    EXPECT_FALSE(OpenSealedWith(stranger.read_key(), sealed.data(), sealed.size(), "S_SOLVER_STATUS"))
        << RoleToString(role);
  }
}

TEST_F(SealedMessageTest, DuringARotationThePreviousReadKeyStillOpens) {
  const KeySet new_server = KeySet::ForRole(other_root_, Role::kServer);
  ASSERT_TRUE(Sign(&status_, "S_SOLVER_STATUS", 7, 1, server_.tagger()));
  const Bytes plain = Encode(status_);
  // The server in its grace: seals with the previous (old) read key.
  SetSealing(new_server.read_key(), &server_.read_key(), true, /*seal_with_previous=*/true);
  const Bytes sealed = ToBytes(SealForChannel(ByteView{plain.data(), plain.size()}, "S_SOLVER_STATUS"));
  EXPECT_TRUE(OpenSealedWith(server_.read_key(), sealed.data(), sealed.size(), "S_SOLVER_STATUS"))
      << "a receiver not yet reloaded";
  // A reloaded receiver holds the new key and keeps the old one.
  SetSealing(new_server.read_key(), &server_.read_key(), false);
  EXPECT_TRUE(OpenSealed(sealed.data(), sealed.size(), "S_SOLVER_STATUS").has_value());
  SetSealing(new_server.read_key(), nullptr, false);
  EXPECT_FALSE(OpenSealed(sealed.data(), sealed.size(), "S_SOLVER_STATUS").has_value())
      << "the old key forgotten after the grace";
}

// A subscriber on a real liblcm (memq://) with the read key gets the message as sent; one
// without it gets the envelope, which no snapthread type decodes.
class Collector {
 public:
  void On(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    const auto* p = static_cast<const uint8_t*>(rbuf->data);
    got.emplace_back(p, p + rbuf->data_size);
  }
  std::vector<Bytes> got;
};

TEST_F(SealedMessageTest, ASubscriberGetsTheMessageInsideAndWithoutTheKeyOnlyAnUndecodableEnvelope) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  Collector collector;
  messages::Subscribe<&Collector::On>(lcm, "S_SOLVER_STATUS", &collector);
  ASSERT_TRUE(Sign(&status_, "S_SOLVER_STATUS", 7, 1, server_.tagger()));
  const Bytes plain = Encode(status_);

  SetSealing(server_.read_key(), nullptr, true);
  ASSERT_EQ(messages::Publish(&lcm, "S_SOLVER_STATUS", status_), 0);
  ASSERT_EQ(lcm.handleTimeout(1000), 1);
  ASSERT_EQ(collector.got.size(), 1u);
  EXPECT_EQ(collector.got[0], plain);

  // memq:// queues the published bytes: the envelope is made now, with the session's key,
  // and opened at handleTimeout, where the process holds another session's key.
  ASSERT_EQ(messages::Publish(&lcm, "S_SOLVER_STATUS", status_), 0);
  SetSealing(DeriveReadKey(other_root_), nullptr, false);
  ASSERT_EQ(lcm.handleTimeout(1000), 1);
  ASSERT_EQ(collector.got.size(), 2u);
  EXPECT_TRUE(IsSealed(collector.got[1].data(), collector.got[1].size()));
  solver_status_t decoded;
  std::string why;
  lcm::ReceiveBuffer rb{collector.got[1].data(), static_cast<uint32_t>(collector.got[1].size()), 0};
  EXPECT_FALSE(messages::DecodeAndValidate(&rb, &decoded, &why));
  EXPECT_FALSE(why.empty());
}

}  // namespace
}  // namespace snapthread::auth
