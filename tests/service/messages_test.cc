// Tests of common/messages: channel names, URL resolution, round trips of every
// message over memq://, validation and malformed-buffer fuzzing.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <algorithm>
#include <cstdlib>
#include <memory>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "messages/channels.h"
#include "messages/lcm_url.h"
#include "messages/subscribe.h"
#include "messages/validate.h"
#include "sample_messages.h"

namespace snapthread::messages {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- sample messages (tests/support/sample_messages.h) ------------------------------

using test_support::Sample;
using test_support::SampleShape;

// Equality through the encoding: two messages are equal when their bytes are.
template <class T>
std::vector<uint8_t> Encode(const T& m) {
  std::vector<uint8_t> buf(m.getEncodedSize());
  EXPECT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  return buf;
}

// ---- Channels / URL / clock ----------------------------------------------------------

TEST(TransportChannelsTest, NamesArePrefixedBySession) {
  Channels c("LAB_2");
  EXPECT_EQ(c.device_state, "LAB_2_DEVICE_STATE");
  EXPECT_EQ(c.force_model, "LAB_2_FORCE_MODEL");
  EXPECT_EQ(c.shape, "LAB_2_SHAPE");
  EXPECT_EQ(c.solver_status, "LAB_2_SOLVER_STATUS");
  EXPECT_EQ(c.device_status, "LAB_2_DEVICE_STATUS");
  EXPECT_EQ(c.command, "LAB_2_COMMAND");
  EXPECT_EQ(c.command_reply, "LAB_2_COMMAND_REPLY");
  EXPECT_EQ(Channels().device_state, "SNAPTHREAD_DEVICE_STATE");
}

TEST(TransportChannelsTest, RejectsInvalidSessionNames) {
  for (const char* bad : {"", "A B", "A-B", "A.B", "ÄB", "A/B", "A*"}) {
    EXPECT_THROW(Channels{bad}, std::invalid_argument) << bad;
    EXPECT_FALSE(IsValidSessionName(bad)) << bad;
  }
  // Every channel must stay within LCM's 63-byte channel names.
  const std::string longest(kMaxSessionNameLength, 'S');
  EXPECT_TRUE(IsValidSessionName(longest));
  EXPECT_LE(Channels(longest).solver_status.size(), 63u);
  EXPECT_LE(Channels(longest).device_status.size(), 63u);
  EXPECT_FALSE(IsValidSessionName(longest + "S"));
  EXPECT_THROW(Channels{longest + "S"}, std::invalid_argument);
  try {
    Channels c("bad name");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bad name"), std::string::npos);
  }
}

TEST(TransportLcmUrlTest, FlagThenEnvironmentThenDefault) {
  const char* saved = std::getenv("LCM_DEFAULT_URL");
  std::string saved_value = saved ? saved : "";
  unsetenv("LCM_DEFAULT_URL");
  EXPECT_EQ(ResolveLcmUrl(""), "udpm://239.255.76.67:7667?ttl=0");
  setenv("LCM_DEFAULT_URL", "memq://", 1);
  EXPECT_EQ(ResolveLcmUrl(""), "memq://");
  EXPECT_EQ(ResolveLcmUrl("udpm://239.255.76.67:7700?ttl=1"), "udpm://239.255.76.67:7700?ttl=1");
  if (saved) {
    setenv("LCM_DEFAULT_URL", saved_value.c_str(), 1);
  } else {
    unsetenv("LCM_DEFAULT_URL");
  }
}

TEST(TransportLcmUrlTest, ReceiversAskForABufferTheKernelGrants) {
  const std::string udpm = "udpm://239.255.76.67:7667";
  EXPECT_EQ(WithReceiveBuffer(udpm + "?ttl=0", 8388608, 4194304), udpm + "?ttl=0&recv_buf_size=4194304");
  EXPECT_EQ(WithReceiveBuffer(udpm, 1048576, 4194304), udpm + "?recv_buf_size=1048576");
  EXPECT_EQ(WithReceiveBuffer(udpm + "?ttl=1", 1048576, 0), udpm + "?ttl=1&recv_buf_size=1048576");
  // The user's own size stays; other providers have no such option.
  EXPECT_EQ(WithReceiveBuffer(udpm + "?recv_buf_size=65536", 1048576, 4194304),
            udpm + "?recv_buf_size=65536");
  EXPECT_EQ(WithReceiveBuffer("memq://", 1048576, 4194304), "memq://");
  EXPECT_EQ(WithReceiveBuffer("file:///tmp/x.lcmlog?mode=r", 1048576, 4194304),
            "file:///tmp/x.lcmlog?mode=r");
}

// ---- memq:// round trips ------------------------------------------------------------

template <class T>
class Catcher {
 public:
  void Handle(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
    T msg;
    std::string why;
    if (DecodeAndValidate(rbuf, &msg, &why)) {
      got.push_back(msg);
    } else {
      rejected.push_back(why);
    }
  }
  std::vector<T> got;
  std::vector<std::string> rejected;
};

template <class T>
void RoundTrip(const T& sent) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  Catcher<T> catcher;
  messages::Subscribe<&Catcher<T>::Handle>(lcm, "RT_TEST", &catcher);
  ASSERT_EQ(lcm.publish("RT_TEST", &sent), 0);
  for (int i = 0; i < 10 && catcher.got.empty() && catcher.rejected.empty(); ++i) {
    lcm.handleTimeout(100);
  }
  ASSERT_TRUE(catcher.rejected.empty()) << catcher.rejected.front();
  ASSERT_EQ(catcher.got.size(), 1u);
  EXPECT_EQ(Encode(catcher.got.front()), Encode(sent));
}

TEST(TransportRoundTripTest, DeviceState) { RoundTrip(Sample<device_state_t>()); }
TEST(TransportRoundTripTest, ForceModel) {
  RoundTrip(Sample<force_model_t>());
}
TEST(TransportRoundTripTest, ThreadShape) {
  RoundTrip(SampleShape(0));
  RoundTrip(SampleShape(1));
  RoundTrip(SampleShape(200));
}
TEST(TransportRoundTripTest, SolverStatus) { RoundTrip(Sample<solver_status_t>()); }
TEST(TransportRoundTripTest, DeviceStatus) { RoundTrip(Sample<device_status_t>()); }
TEST(TransportRoundTripTest, Command) { RoundTrip(Sample<command_t>()); }
TEST(TransportRoundTripTest, CommandReply) { RoundTrip(Sample<command_reply_t>()); }

TEST(TransportRoundTripTest, ForceModelFieldsSurvive) {
  // One explicit field-by-field check so that an encoding comparison bug cannot hide one.
  const force_model_t sent = Sample<force_model_t>();
  const auto bytes = Encode(sent);
  force_model_t got;
  std::string why;
  ASSERT_TRUE(DecodeAndValidate(bytes.data(), static_cast<int>(bytes.size()), &got, &why)) << why;
  EXPECT_EQ(got.seq, sent.seq);
  EXPECT_EQ(got.device_seq, sent.device_seq);
  EXPECT_EQ(got.device_utime, sent.device_utime);
  EXPECT_EQ(got.status, sent.status);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(got.u0[i], sent.u0[i]);
    EXPECT_EQ(got.f0[i], sent.f0[i]);
    for (int j = 0; j < 3; ++j) EXPECT_EQ(got.K[i][j], sent.K[i][j]);
  }
}

// ---- Validate -------------------------------------------------------------------------

TEST(TransportValidateTest, AcceptsSamples) {
  std::string why;
  EXPECT_TRUE(Validate(Sample<device_state_t>(), &why)) << why;
  EXPECT_TRUE(Validate(Sample<force_model_t>(), &why)) << why;
  EXPECT_TRUE(Validate(SampleShape(5), &why)) << why;
  EXPECT_TRUE(Validate(Sample<solver_status_t>(), &why)) << why;
  EXPECT_TRUE(Validate(Sample<device_status_t>(), &why)) << why;
  EXPECT_TRUE(Validate(Sample<command_t>(), &why)) << why;
  EXPECT_TRUE(Validate(Sample<command_reply_t>(), &why)) << why;
}

TEST(TransportValidateTest, RejectsNonFiniteDeviceState) {
  for (double bad : {kNaN, kInf, -kInf}) {
    for (int i = 0; i < 3; ++i) {
      auto m = Sample<device_state_t>();
      m.position[i] = bad;
      std::string why;
      EXPECT_FALSE(Validate(m, &why));
      EXPECT_NE(why.find("position"), std::string::npos) << why;
    }
    for (int i = 0; i < 4; ++i) {
      auto m = Sample<device_state_t>();
      m.orientation[i] = bad;
      EXPECT_FALSE(Validate(m, nullptr));
    }
  }
}

TEST(TransportValidateTest, QuaternionNormRange) {
  auto m = Sample<device_state_t>();
  m.orientation[0] = 0.0;  // zero quaternion
  EXPECT_FALSE(Validate(m, nullptr));
  m.orientation[0] = 3.0;
  EXPECT_FALSE(Validate(m, nullptr));
  m.orientation[0] = 0.6;
  EXPECT_TRUE(Validate(m, nullptr));
  m.orientation[0] = 1.9;
  EXPECT_TRUE(Validate(m, nullptr));
}

TEST(TransportValidateTest, RejectsNonFiniteForceModel) {
  for (double bad : {kNaN, kInf, -kInf}) {
    for (int i = 0; i < 3; ++i) {
      auto a = Sample<force_model_t>(); a.u0[i] = bad; EXPECT_FALSE(Validate(a, nullptr));
      auto b = Sample<force_model_t>(); b.f0[i] = bad; EXPECT_FALSE(Validate(b, nullptr));
      auto c = Sample<force_model_t>(); c.torque0[i] = bad; EXPECT_FALSE(Validate(c, nullptr));
      for (int j = 0; j < 3; ++j) {
        auto d = Sample<force_model_t>(); d.K[i][j] = bad;
        std::string why;
        EXPECT_FALSE(Validate(d, &why));
        EXPECT_NE(why.find("K"), std::string::npos);
      }
    }
    auto e = Sample<force_model_t>(); e.residual = bad; EXPECT_FALSE(Validate(e, nullptr));
  }
  auto s = Sample<force_model_t>();
  s.status = force_model_t::STATUS_SNAPPING;  // the last status constant
  EXPECT_TRUE(Validate(s, nullptr));
  s.status = force_model_t::STATUS_SNAPPING + 1;
  EXPECT_FALSE(Validate(s, nullptr));
  s.status = -1;
  EXPECT_FALSE(Validate(s, nullptr));
  auto t = Sample<force_model_t>();
  t.has_torque = 2;
  EXPECT_FALSE(Validate(t, nullptr));
}

TEST(TransportValidateTest, ShapeCountsMustAgree) {
  auto m = SampleShape(4);
  m.num_nodes = 5;
  std::string why;
  EXPECT_FALSE(Validate(m, &why));
  EXPECT_NE(why.find("num_nodes"), std::string::npos) << why;
  auto r = SampleShape(4);
  r.positions[2].resize(2);
  EXPECT_FALSE(Validate(r, &why));
  auto neg = SampleShape(0);
  neg.num_nodes = -1;
  EXPECT_FALSE(Validate(neg, nullptr));
  auto big = SampleShape(0);
  big.num_nodes = kMaxShapeNodes + 1;
  EXPECT_FALSE(Validate(big, nullptr));
  auto nan = SampleShape(3);
  nan.positions[1][2] = kNaN;
  EXPECT_FALSE(Validate(nan, nullptr));
  auto inf = SampleShape(3);
  inf.force_newtons[0] = kInf;
  EXPECT_FALSE(Validate(inf, nullptr));
}

TEST(TransportValidateTest, StatusesAndCommands) {
  auto s = Sample<solver_status_t>();
  s.residual = kNaN;
  EXPECT_FALSE(Validate(s, nullptr));
  auto d = Sample<device_status_t>();
  d.lateness_us_p99 = kInf;
  EXPECT_FALSE(Validate(d, nullptr));
  auto c = Sample<command_t>();
  c.command = 0;
  EXPECT_FALSE(Validate(c, nullptr));
  c.command = command_t::SET_METHOD;
  EXPECT_TRUE(Validate(c, nullptr));
  c.argument.assign(kMaxStringBytes + 1, 'x');
  EXPECT_FALSE(Validate(c, nullptr));
}

TEST(TransportValidateTest, CommandReplies) {
  auto r = Sample<command_reply_t>();
  std::string why;
  EXPECT_TRUE(Validate(r, &why)) << why;
  r.ok = 2;  // ok is 0 or 1
  EXPECT_FALSE(Validate(r, &why));
  EXPECT_NE(why.find("ok"), std::string::npos) << why;
  r.ok = 0;
  r.command = 0;  // answers one of command_t's commands
  EXPECT_FALSE(Validate(r, nullptr));
  r.command = command_t::RESET;
  EXPECT_TRUE(Validate(r, nullptr));
  r.message.assign(kMaxCommandReplyBytes, 'x');
  EXPECT_TRUE(Validate(r, nullptr));
  r.message += 'x';  // a reply is short text for a terminal
  EXPECT_FALSE(Validate(r, &why));
  EXPECT_NE(why.find("message"), std::string::npos) << why;
}

// ---- DecodeAndValidate against malformed buffers ------------------------------------------

template <class T>
void ExpectTruncationsRejected(const T& sample) {
  const auto bytes = Encode(sample);
  T out;
  std::string why;
  ASSERT_TRUE(DecodeAndValidate(bytes.data(), static_cast<int>(bytes.size()), &out, &why)) << why;
  for (size_t len = 0; len < bytes.size(); ++len) {
    EXPECT_FALSE(DecodeAndValidate(bytes.data(), static_cast<int>(len), &out, &why)) << len;
  }
  // Oversized: trailing bytes after a valid message are refused too.
  auto longer = bytes;
  longer.resize(bytes.size() + 16, 0xAB);
  EXPECT_FALSE(DecodeAndValidate(longer.data(), static_cast<int>(longer.size()), &out, &why));
  EXPECT_NE(why.find("trailing"), std::string::npos) << why;
  // Wrong type (hash mismatch).
  const auto other = Encode(Sample<command_t>());
  if constexpr (!std::is_same_v<T, command_t>) {
    EXPECT_FALSE(DecodeAndValidate(other.data(), static_cast<int>(other.size()), &out, &why));
  }
}

TEST(TransportDecodeTest, TruncatedOversizedAndWrongTypeRejected) {
  ExpectTruncationsRejected(Sample<device_state_t>());
  ExpectTruncationsRejected(Sample<force_model_t>());
  ExpectTruncationsRejected(SampleShape(7));
  ExpectTruncationsRejected(Sample<solver_status_t>());
  ExpectTruncationsRejected(Sample<device_status_t>());
  ExpectTruncationsRejected(Sample<command_t>());
  ExpectTruncationsRejected(Sample<command_reply_t>());
}

TEST(TransportDecodeTest, HugeShapeCountIsRefusedBeforeAllocation) {
  auto m = SampleShape(2);
  auto bytes = Encode(m);
  // num_nodes sits after hash, utime, seq and the two strings (4-byte length + bytes + NUL).
  const size_t pos = 24 + 4 + m.scene.size() + 1 + 4 + m.model.size() + 1;
  for (uint32_t bad : {0x7fffffffu, 0x80000000u, 0xffffffffu, 100001u, 3u}) {
    bytes[pos + 0] = static_cast<uint8_t>(bad >> 24);
    bytes[pos + 1] = static_cast<uint8_t>(bad >> 16);
    bytes[pos + 2] = static_cast<uint8_t>(bad >> 8);
    bytes[pos + 3] = static_cast<uint8_t>(bad);
    thread_shape_t out;
    std::string why;
    EXPECT_FALSE(DecodeAndValidate(bytes.data(), static_cast<int>(bytes.size()), &out, &why)) << bad;
  }
}

TEST(TransportDecodeTest, CorruptStringLengthDoesNotThrow) {
  auto m = Sample<device_state_t>();
  auto bytes = Encode(m);
  // device_id's length field follows hash, utime and seq.
  for (uint32_t bad : {0u, 0xffffffffu, 0x80000000u, 0x7fffffffu}) {
    bytes[24] = static_cast<uint8_t>(bad >> 24);
    bytes[25] = static_cast<uint8_t>(bad >> 16);
    bytes[26] = static_cast<uint8_t>(bad >> 8);
    bytes[27] = static_cast<uint8_t>(bad);
    device_state_t out;
    std::string why;
    EXPECT_NO_THROW(
        EXPECT_FALSE(DecodeAndValidate(bytes.data(), static_cast<int>(bytes.size()), &out, &why)))
        << bad;
  }
}

TEST(TransportDecodeTest, StringWithoutItsNulIsRefused) {
  // lcm-gen's decoder skips a string's last byte without looking at it.
  auto m = Sample<device_state_t>();
  auto bytes = Encode(m);
  const size_t nul = 24 + 4 + m.device_id.size();
  ASSERT_EQ(bytes[nul], 0);
  bytes[nul] = 0xF9;
  device_state_t out;
  std::string why;
  EXPECT_FALSE(DecodeAndValidate(bytes.data(), static_cast<int>(bytes.size()), &out, &why));
  EXPECT_NE(why.find("NUL"), std::string::npos) << why;
}

// Random garbage, and valid messages with random byte flips: never a crash, a throw or
// an accepted message with non-finite content.
template <class T>
void Fuzz(const T& sample, uint32_t seed, int* accepted) {
  std::mt19937 rng(seed);
  const auto valid = Encode(sample);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<int> len(0, static_cast<int>(valid.size()) * 2 + 8);
  for (int iter = 0; iter < 3000; ++iter) {
    std::vector<uint8_t> buf;
    if (iter % 2 == 0) {
      buf.resize(len(rng));
      for (auto& b : buf) b = static_cast<uint8_t>(byte(rng));
      // Keep the right hash half of the time so the decoder goes past the first check.
      if (iter % 4 == 0 && buf.size() >= 8) std::copy(valid.begin(), valid.begin() + 8, buf.begin());
    } else {
      buf = valid;
      std::uniform_int_distribution<size_t> where(8, buf.size() - 1);
      const int flips = 1 + iter % 4;
      for (int f = 0; f < flips; ++f) buf[where(rng)] = static_cast<uint8_t>(byte(rng));
    }
    T out;
    std::string why;
    bool ok = false;
    EXPECT_NO_THROW(ok = DecodeAndValidate(buf.data(), static_cast<int>(buf.size()), &out, &why));
    if (ok) {
      ++*accepted;
      EXPECT_TRUE(Validate(out, &why)) << why;
    }
  }
}

TEST(TransportDecodeTest, FuzzEveryType) {
  int accepted = 0;
  Fuzz(Sample<device_state_t>(), 1, &accepted);
  Fuzz(Sample<force_model_t>(), 2, &accepted);
  Fuzz(SampleShape(10), 3, &accepted);
  Fuzz(Sample<solver_status_t>(), 4, &accepted);
  Fuzz(Sample<device_status_t>(), 5, &accepted);
  Fuzz(Sample<command_t>(), 6, &accepted);
  Fuzz(Sample<command_reply_t>(), 7, &accepted);
  // Flipping bytes of doubles often still gives a valid message: the fuzz reaches Validate.
  EXPECT_GT(accepted, 0);
}

TEST(TransportDecodeTest, GarbageOverMemqIsCountedNotFatal) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  Catcher<force_model_t> catcher;
  messages::Subscribe<&Catcher<force_model_t>::Handle>(lcm, "FUZZ", &catcher);
  std::mt19937 rng(99);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int i = 0; i < 200; ++i) {
    std::vector<uint8_t> buf(1 + i % 300);
    for (auto& b : buf) b = static_cast<uint8_t>(byte(rng));
    lcm.publish("FUZZ", buf.data(), static_cast<unsigned>(buf.size()));
  }
  auto bad = Sample<force_model_t>();
  bad.K[1][1] = kNaN;
  lcm.publish("FUZZ", &bad);
  const auto good = Sample<force_model_t>();
  lcm.publish("FUZZ", &good);
  while (lcm.handleTimeout(10) > 0) {
  }
  EXPECT_EQ(catcher.rejected.size(), 201u);
  EXPECT_EQ(catcher.got.size(), 1u);
}

}  // namespace
}  // namespace snapthread::messages
