// Sign / VerifyEncoded on every message type: round trips, any changed byte refused,
// another key or channel refused, the tag where the type puts it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "auth/message_mac.h"
#include "auth/session_key.h"
#include "sample_messages.h"

namespace snapthread::auth {
namespace {

using test_support::Encode;
using test_support::Sample;

constexpr const char* kChannel = "SNAPTHREAD_TEST";
constexpr int64_t kEpoch = 0x1234567890abcdefLL;

template <class Msg>
class MessageMacTest : public ::testing::Test {
 protected:
  SessionKey key_ = SessionKey::Generate();
};

using AllTypes = ::testing::Types<device_state_t, force_model_t, thread_shape_t, solver_status_t,
                                  device_status_t, command_t>;
TYPED_TEST_SUITE(MessageMacTest, AllTypes);

TYPED_TEST(MessageMacTest, SignedMessageVerifiesAndDecodesWithItsFields) {
  TypeParam m = Sample<TypeParam>();
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 1001, this->key_));
  EXPECT_EQ(m.epoch, kEpoch);
  EXPECT_EQ(m.auth_seq, 1001);
  EXPECT_FALSE(std::all_of(std::begin(m.mac), std::end(m.mac), [](uint8_t b) { return b == 0; }));

  const std::vector<uint8_t> bytes = Encode(m);
  EXPECT_TRUE(VerifyEncoded(bytes.data(), bytes.size(), kChannel, this->key_));
  // The decoded message carries the same freshness fields and tag (logs keep them).
  TypeParam back{};
  ASSERT_EQ(back.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  EXPECT_EQ(back.epoch, kEpoch);
  EXPECT_EQ(back.auth_seq, 1001);
  EXPECT_EQ(0, std::memcmp(back.mac, m.mac, kMacBytes));
  EXPECT_EQ(Encode(back), bytes);
}

TYPED_TEST(MessageMacTest, TagIsTheLastBytesOfTheEncoding) {
  // VerifyEncoded relies on `byte mac[32]` being the last field of every type.
  TypeParam m = Sample<TypeParam>();
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 5, this->key_));
  const std::vector<uint8_t> bytes = Encode(m);
  ASSERT_GE(bytes.size(), kMacBytes);
  EXPECT_EQ(0, std::memcmp(bytes.data() + bytes.size() - kMacBytes, m.mac, kMacBytes));
}

TYPED_TEST(MessageMacTest, AnyFlippedBitAnywhereIsRefused) {
  TypeParam m = Sample<TypeParam>();
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 77, this->key_));
  const std::vector<uint8_t> good = Encode(m);
  int accepted = 0;
  for (size_t i = 0; i < good.size(); ++i) {
    for (const uint8_t bit : {0x01, 0x10, 0x80}) {
      std::vector<uint8_t> bad = good;
      bad[i] ^= bit;
      if (VerifyEncoded(bad.data(), bad.size(), kChannel, this->key_)) {
        ++accepted;
        ADD_FAILURE() << "byte " << i << " of " << good.size() << " flipped with " << int(bit)
                      << " still verifies";
      }
    }
  }
  EXPECT_EQ(accepted, 0);
  EXPECT_TRUE(VerifyEncoded(good.data(), good.size(), kChannel, this->key_));
}

TYPED_TEST(MessageMacTest, TruncatedOrExtendedBufferIsRefused) {
  TypeParam m = Sample<TypeParam>();
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 78, this->key_));
  std::vector<uint8_t> bytes = Encode(m);
  EXPECT_FALSE(VerifyEncoded(bytes.data(), bytes.size() - 1, kChannel, this->key_));
  EXPECT_FALSE(VerifyEncoded(bytes.data() + 1, bytes.size() - 1, kChannel, this->key_));
  bytes.push_back(0);
  EXPECT_FALSE(VerifyEncoded(bytes.data(), bytes.size(), kChannel, this->key_));
  EXPECT_FALSE(VerifyEncoded(bytes.data(), 0, kChannel, this->key_));
  EXPECT_FALSE(VerifyEncoded(nullptr, 100, kChannel, this->key_));
}

TYPED_TEST(MessageMacTest, AnotherKeyOrNoKeyIsRefused) {
  TypeParam m = Sample<TypeParam>();
  const SessionKey rogue = SessionKey::Generate();
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 9, rogue));
  std::vector<uint8_t> bytes = Encode(m);
  EXPECT_FALSE(VerifyEncoded(bytes.data(), bytes.size(), kChannel, this->key_));
  EXPECT_TRUE(VerifyEncoded(bytes.data(), bytes.size(), kChannel, rogue));
  // A valid encoding with the genuine epoch and sequence but no key: zero tag.
  std::fill(m.mac, m.mac + kMacBytes, uint8_t{0});
  bytes = Encode(m);
  EXPECT_FALSE(VerifyEncoded(bytes.data(), bytes.size(), kChannel, this->key_));
}

TYPED_TEST(MessageMacTest, TagIsBoundToTheChannel) {
  TypeParam m = Sample<TypeParam>();
  ASSERT_TRUE(Sign(&m, "S_GRASP_LEFT", kEpoch, 9, this->key_));
  const std::vector<uint8_t> bytes = Encode(m);
  EXPECT_TRUE(VerifyEncoded(bytes.data(), bytes.size(), "S_GRASP_LEFT", this->key_));
  EXPECT_FALSE(VerifyEncoded(bytes.data(), bytes.size(), "S_GRASP_RIGHT", this->key_));
  EXPECT_FALSE(VerifyEncoded(bytes.data(), bytes.size(), "", this->key_));
}

TYPED_TEST(MessageMacTest, TagCoversEpochAndSequence) {
  TypeParam a = Sample<TypeParam>();
  TypeParam b = Sample<TypeParam>();
  TypeParam c = Sample<TypeParam>();
  TypeParam d = Sample<TypeParam>();
  ASSERT_TRUE(Sign(&a, kChannel, kEpoch, 10, this->key_));
  ASSERT_TRUE(Sign(&b, kChannel, kEpoch, 10, this->key_));
  ASSERT_TRUE(Sign(&c, kChannel, kEpoch, 11, this->key_));
  ASSERT_TRUE(Sign(&d, kChannel, kEpoch + 1, 10, this->key_));
  EXPECT_EQ(0, std::memcmp(a.mac, b.mac, kMacBytes));  // deterministic
  EXPECT_NE(0, std::memcmp(a.mac, c.mac, kMacBytes));
  EXPECT_NE(0, std::memcmp(a.mac, d.mac, kMacBytes));
  // Re-labelling a signed message with another sequence number breaks it.
  a.auth_seq = 11;
  const std::vector<uint8_t> bytes = Encode(a);
  EXPECT_FALSE(VerifyEncoded(bytes.data(), bytes.size(), kChannel, this->key_));
}

TEST(MessageMacEdgeTest, StringWithEmbeddedNulIsNotSigned) {
  // LCM encodes strings up to their first NUL but sizes them by length(): such a message
  // would go out with bytes the tag does not describe, so Sign refuses it.
  const SessionKey key = SessionKey::Generate();
  command_t m = Sample<command_t>();
  m.argument = std::string("zeeman\0/etc/passwd", 18);
  EXPECT_FALSE(Sign(&m, kChannel, kEpoch, 1, key));
  EXPECT_TRUE(std::all_of(std::begin(m.mac), std::end(m.mac), [](uint8_t b) { return b == 0; }));
}

TEST(MessageMacEdgeTest, LargeShapeSignsAndVerifies) {
  const SessionKey key = SessionKey::Generate();
  thread_shape_t m = test_support::SampleShape(50000);
  ASSERT_TRUE(Sign(&m, kChannel, kEpoch, 1, key));
  std::vector<uint8_t> bytes = Encode(m);
  EXPECT_TRUE(VerifyEncoded(bytes.data(), bytes.size(), kChannel, key));
  bytes[bytes.size() / 2] ^= 1;
  EXPECT_FALSE(VerifyEncoded(bytes.data(), bytes.size(), kChannel, key));
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
