// Sign / VerifyMac / VerifySignature on every message type (auth/message_mac.h): the
// trailer a Tagger fills in, MAC and signature each refusing any changed byte they cover,
// zero tags refused, another key or channel refused, signature2 by a previous key, the
// tags where the type puts them, and KeyIdToWire.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/role_keys.h"
#include "auth/session_key.h"
#include "sample_messages.h"

namespace snapthread::auth {
namespace {

using test_support::Encode;
using test_support::Sample;

constexpr const char* kChannel = "SNAPTHREAD_TEST";
constexpr int64_t kEpoch = 0x1234567890abcdefLL;

bool AllZero(const uint8_t* bytes, size_t n) {
  return std::all_of(bytes, bytes + n, [](uint8_t b) { return b == 0; });
}

template <class Msg>
class MessageMacTest : public ::testing::Test {
 protected:
  SessionKey root_ = SessionKey::Generate();
  KeySet device_ = KeySet::ForRole(root_, Role::kDevice, "hand");  // MACs
  KeySet server_ = KeySet::FromRoot(SessionKey::FromBytes(root_.data(), SessionKey::kBytes));  // signs
  const SessionKey& mac_key() const { return *device_.mac_key(); }
  const PublicKey& server_key() const { return server_.server_public_key(); }
};

using AllTypes = ::testing::Types<device_state_t, force_model_t, thread_shape_t, solver_status_t,
                                  device_status_t, command_t, command_reply_t>;
TYPED_TEST_SUITE(MessageMacTest, AllTypes);

TYPED_TEST(MessageMacTest, MacTaggerFillsTheTrailerAndVerifies) {
  TypeParam m = Sample<TypeParam>();
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 1001, this->device_.tagger()));
  EXPECT_EQ(m.epoch, kEpoch);
  EXPECT_EQ(m.auth_seq, 1001);
  EXPECT_EQ(m.sender_role, static_cast<int8_t>(Role::kDevice));
  EXPECT_EQ(m.sender_name, "hand");
  EXPECT_EQ(m.key_expires, this->device_.expires_unix_s());
  EXPECT_EQ(KeyIdFromWire(m.key_id), this->device_.credential()->key_id);
  EXPECT_FALSE(AllZero(m.mac, kMacBytes));
  EXPECT_TRUE(AllZero(m.signature, kSignatureBytes));
  EXPECT_TRUE(AllZero(m.signature2, kSignatureBytes));

  const std::vector<uint8_t> bytes = Encode(m);
  EXPECT_TRUE(VerifyMac(bytes.data(), bytes.size(), kChannel, this->mac_key()));
  EXPECT_FALSE(VerifySignature(bytes.data(), bytes.size(), kChannel, this->server_key()));
  // The decoded message carries the same trailer (logs keep it) and encodes to the same bytes.
  TypeParam back{};
  ASSERT_EQ(back.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  EXPECT_EQ(back.auth_seq, 1001);
  EXPECT_EQ(back.sender_name, "hand");
  EXPECT_EQ(0, std::memcmp(back.mac, m.mac, kMacBytes));
  EXPECT_EQ(Encode(back), bytes);
}

TYPED_TEST(MessageMacTest, ServerTaggerSignsWithoutMac) {
  TypeParam m = Sample<TypeParam>();
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 7, this->server_.tagger()));
  EXPECT_EQ(m.sender_role, static_cast<int8_t>(Role::kServer));
  EXPECT_EQ(m.key_id, 0);
  EXPECT_EQ(m.key_expires, 0);
  EXPECT_TRUE(AllZero(m.mac, kMacBytes));
  EXPECT_FALSE(AllZero(m.signature, kSignatureBytes));
  EXPECT_TRUE(AllZero(m.signature2, kSignatureBytes));
  const std::vector<uint8_t> bytes = Encode(m);
  EXPECT_TRUE(VerifySignature(bytes.data(), bytes.size(), kChannel, this->server_key()));
  // A zero MAC verifies under no key.
  EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), kChannel, this->mac_key()));
  EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), kChannel, this->root_));
}

TYPED_TEST(MessageMacTest, TagsAreTheLastBytesOfTheEncoding) {
  TypeParam m = Sample<TypeParam>();
  Tagger both = this->device_.tagger();
  both.signer = this->server_.tagger().signer;
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 5, both));
  const std::vector<uint8_t> bytes = Encode(m);
  ASSERT_GE(bytes.size(), kTagBytes);
  const uint8_t* tags = bytes.data() + bytes.size() - kTagBytes;
  EXPECT_EQ(0, std::memcmp(tags, m.signature, kSignatureBytes));
  EXPECT_EQ(0, std::memcmp(tags + kSignatureBytes, m.signature2, kSignatureBytes));
  EXPECT_EQ(0, std::memcmp(tags + 2 * kSignatureBytes, m.mac, kMacBytes));
  EXPECT_TRUE(VerifyMac(bytes.data(), bytes.size(), kChannel, this->mac_key()));
  EXPECT_TRUE(VerifySignature(bytes.data(), bytes.size(), kChannel, this->server_key()));
}

TYPED_TEST(MessageMacTest, MacCoversEveryByte) {
  TypeParam m = Sample<TypeParam>();
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 77, this->device_.tagger()));
  const std::vector<uint8_t> good = Encode(m);
  int accepted = 0;
  for (size_t i = 0; i < good.size(); ++i) {
    for (const uint8_t bit : {0x01, 0x80}) {
      std::vector<uint8_t> bad = good;
      bad[i] ^= bit;
      if (VerifyMac(bad.data(), bad.size(), kChannel, this->mac_key())) {
        ++accepted;
        ADD_FAILURE() << "byte " << i << " of " << good.size() << " flipped with " << int(bit) << " still verifies";
      }
    }
  }
  EXPECT_EQ(accepted, 0);
  EXPECT_TRUE(VerifyMac(good.data(), good.size(), kChannel, this->mac_key()));
}

TYPED_TEST(MessageMacTest, SignatureCoversEveryByteButTheOtherTagSlots) {
  // The signature is over the encoding with signature, signature2 and mac zeroed: every
  // other byte, and its own slot, is covered. (signature2 and mac are checked by their
  // own keys, or are zero.)
  TypeParam m = Sample<TypeParam>();
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 78, this->server_.tagger()));
  const std::vector<uint8_t> good = Encode(m);
  const size_t others = good.size() - kTagBytes + kSignatureBytes;  // signature2 and mac
  int accepted = 0;
  for (size_t i = 0; i < others; ++i) {
    std::vector<uint8_t> bad = good;
    bad[i] ^= 0x01;
    if (VerifySignature(bad.data(), bad.size(), kChannel, this->server_key())) {
      ++accepted;
      ADD_FAILURE() << "byte " << i << " of " << good.size() << " flipped still verifies";
    }
  }
  EXPECT_EQ(accepted, 0);
  EXPECT_TRUE(VerifySignature(good.data(), good.size(), kChannel, this->server_key()));
}

TYPED_TEST(MessageMacTest, TruncatedOrExtendedBufferIsRefused) {
  TypeParam m = Sample<TypeParam>();
  Tagger both = this->device_.tagger();
  both.signer = this->server_.tagger().signer;
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 78, both));
  std::vector<uint8_t> bytes = Encode(m);
  for (const auto& [data, size] : std::vector<std::pair<const uint8_t*, size_t>>{
           {bytes.data(), bytes.size() - 1}, {bytes.data() + 1, bytes.size() - 1}, {bytes.data(), 0}, {nullptr, 100}}) {
    EXPECT_FALSE(VerifyMac(data, size, kChannel, this->mac_key()));
    EXPECT_FALSE(VerifySignature(data, size, kChannel, this->server_key()));
  }
  bytes.push_back(0);
  EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), kChannel, this->mac_key()));
  EXPECT_FALSE(VerifySignature(bytes.data(), bytes.size(), kChannel, this->server_key()));
}

TYPED_TEST(MessageMacTest, AnotherKeyOrZeroTagsAreRefused) {
  TypeParam m = Sample<TypeParam>();
  const SessionKey other_root = SessionKey::Generate();
  const KeySet other_device = KeySet::ForRole(other_root, Role::kDevice, "hand");
  const KeySet other_server = KeySet::ForRole(other_root, Role::kServer);
  Tagger both = other_device.tagger();
  both.signer = other_server.tagger().signer;
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 9, both));
  std::vector<uint8_t> bytes = Encode(m);
  EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), kChannel, this->mac_key()));
  EXPECT_FALSE(VerifySignature(bytes.data(), bytes.size(), kChannel, this->server_key()));
  EXPECT_TRUE(VerifyMac(bytes.data(), bytes.size(), kChannel, *other_device.mac_key()));
  EXPECT_TRUE(VerifySignature(bytes.data(), bytes.size(), kChannel, other_server.server_public_key()));
  // Another role of the same name holds another key: an operator "hand" is not the device.
  const KeySet op = KeySet::ForRole(this->root_, Role::kOperator, "hand");
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 10, op.tagger()));
  bytes = Encode(m);
  EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), kChannel, this->mac_key()));
  // A valid encoding with the genuine epoch and sequence but no key: zero tags.
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 11, Tagger{}));
  bytes = Encode(m);
  EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), kChannel, this->mac_key()));
  EXPECT_FALSE(VerifySignature(bytes.data(), bytes.size(), kChannel, this->server_key()));
}

TYPED_TEST(MessageMacTest, TagsAreBoundToTheChannel) {
  TypeParam m = Sample<TypeParam>();
  Tagger both = this->device_.tagger();
  both.signer = this->server_.tagger().signer;
  ASSERT_TRUE(Sign(&m, "S_GRASP_LEFT", kEpoch, 9, both));
  const std::vector<uint8_t> bytes = Encode(m);
  EXPECT_TRUE(VerifyMac(bytes.data(), bytes.size(), "S_GRASP_LEFT", this->mac_key()));
  EXPECT_TRUE(VerifySignature(bytes.data(), bytes.size(), "S_GRASP_LEFT", this->server_key()));
  for (const char* other : {"S_GRASP_RIGHT", "", "S_GRASP_LEF"}) {
    EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), other, this->mac_key())) << other;
    EXPECT_FALSE(VerifySignature(bytes.data(), bytes.size(), other, this->server_key())) << other;
  }
}

TYPED_TEST(MessageMacTest, TagsCoverEpochSequenceAndSender) {
  TypeParam a = Sample<TypeParam>(), b = Sample<TypeParam>(), c = Sample<TypeParam>(), d = Sample<TypeParam>();
  const Tagger& t = this->device_.tagger();
  ASSERT_TRUE(Sign(&a, kChannel, kEpoch, 10, t));
  ASSERT_TRUE(Sign(&b, kChannel, kEpoch, 10, t));
  ASSERT_TRUE(Sign(&c, kChannel, kEpoch, 11, t));
  ASSERT_TRUE(Sign(&d, kChannel, kEpoch + 1, 10, t));
  EXPECT_EQ(0, std::memcmp(a.mac, b.mac, kMacBytes));  // deterministic
  EXPECT_NE(0, std::memcmp(a.mac, c.mac, kMacBytes));
  EXPECT_NE(0, std::memcmp(a.mac, d.mac, kMacBytes));
  // Re-labelling a tagged message (sequence, role, name) breaks it.
  TypeParam relabelled = a;
  relabelled.auth_seq = 11;
  std::vector<uint8_t> bytes = Encode(relabelled);
  EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), kChannel, this->mac_key()));
  relabelled = a;
  relabelled.sender_role = static_cast<int8_t>(Role::kOperator);
  bytes = Encode(relabelled);
  EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), kChannel, this->mac_key()));
  relabelled = a;
  relabelled.sender_name = "hanD";
  bytes = Encode(relabelled);
  EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), kChannel, this->mac_key()));
}

TYPED_TEST(MessageMacTest, Signature2OfThePreviousKeyVerifies) {
  // During a rotation's grace the server signs with its new key (signature) and its
  // previous one (signature2): a receiver holding either public key accepts the message.
  const SessionKey old_root = SessionKey::Generate();
  const KeySet old_server = KeySet::ForRole(old_root, Role::kServer);
  Tagger rotating = this->server_.tagger();
  rotating.previous_signer = old_server.tagger().signer;
  TypeParam m = Sample<TypeParam>();
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 12, rotating));
  EXPECT_FALSE(AllZero(m.signature2, kSignatureBytes));
  std::vector<uint8_t> bytes = Encode(m);
  EXPECT_TRUE(VerifySignature(bytes.data(), bytes.size(), kChannel, this->server_key()));
  EXPECT_TRUE(VerifySignature(bytes.data(), bytes.size(), kChannel, old_server.server_public_key()));
  const KeySet stranger = KeySet::ForRole(SessionKey::Generate(), Role::kServer);
  EXPECT_FALSE(VerifySignature(bytes.data(), bytes.size(), kChannel, stranger.server_public_key()));
  // signature2 alone (the slot an old receiver checks) verifies too.
  Tagger previous_only;
  previous_only.previous_signer = old_server.tagger().signer;
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 13, previous_only));
  EXPECT_TRUE(AllZero(m.signature, kSignatureBytes));
  bytes = Encode(m);
  EXPECT_TRUE(VerifySignature(bytes.data(), bytes.size(), kChannel, old_server.server_public_key()));
  EXPECT_FALSE(VerifySignature(bytes.data(), bytes.size(), kChannel, this->server_key()));
}

TEST(MessageMacEdgeTest, StringWithEmbeddedNulIsNotSigned) {
  // LCM encodes strings up to their first NUL but sizes them by length(): such a message
  // would go out with bytes the tags do not describe, so Sign refuses it.
  const SessionKey root = SessionKey::Generate();
  const KeySet op = KeySet::ForRole(root, Role::kOperator, "operator");
  command_t m = Sample<command_t>();
  m.argument = std::string("zeeman\0/etc/passwd", 18);
  EXPECT_FALSE(Sign(&m, kChannel, kEpoch, 1, op.tagger()));
  EXPECT_TRUE(AllZero(m.mac, kMacBytes));
  EXPECT_TRUE(AllZero(m.signature, kSignatureBytes));
}

TEST(MessageMacEdgeTest, LargeShapeSignsAndVerifies) {
  const KeySet server = KeySet::ForRole(SessionKey::Generate(), Role::kServer);
  thread_shape_t m = test_support::SampleShape(50000);
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 1, server.tagger()));
  std::vector<uint8_t> bytes = Encode(m);
  EXPECT_TRUE(VerifySignature(bytes.data(), bytes.size(), kChannel, server.server_public_key()));
  bytes[bytes.size() / 2] ^= 1;
  EXPECT_FALSE(VerifySignature(bytes.data(), bytes.size(), kChannel, server.server_public_key()));
}

TEST(KeyIdWireTest, RoundTripsEveryByte) {
  for (const KeyId& id : {KeyId{}, KeyId{1, 2, 3, 4, 5, 6, 7, 8}, KeyId{0xff, 0, 0x80, 0x7f, 0xfe, 1, 0, 0xff},
                          KeyId{0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff}}) {
    EXPECT_EQ(KeyIdFromWire(KeyIdToWire(id)), id);
  }
  EXPECT_EQ(KeyIdToWire(KeyId{}), 0);
  EXPECT_EQ(KeyIdToWire(KeyId{1, 0, 0, 0, 0, 0, 0, 0}), 1);  // little-endian
  const SessionKey root = SessionKey::Generate();
  const KeyId device_id = KeySet::ForRole(root, Role::kDevice, "hand").credential()->key_id;
  EXPECT_EQ(KeyIdFromWire(KeyIdToWire(device_id)), device_id);
}

TEST(SessionKeyTest, GeneratedKeysDifferAndMove) {
  SessionKey a = SessionKey::Generate();
  const SessionKey b = SessionKey::Generate();
  EXPECT_NE(a.Id(), b.Id());
  EXPECT_NE(0, std::memcmp(a.data(), b.data(), SessionKey::kBytes));
  const std::string id = a.Id();
  SessionKey c = std::move(a);
  EXPECT_EQ(c.Id(), id);
  uint8_t raw[SessionKey::kBytes];
  std::memcpy(raw, c.data(), sizeof raw);
  EXPECT_EQ(SessionKey::FromBytes(raw, sizeof raw).Id(), id);
  EXPECT_THROW(SessionKey::FromBytes(raw, 31), std::invalid_argument);
}

}  // namespace
}  // namespace snapthread::auth
