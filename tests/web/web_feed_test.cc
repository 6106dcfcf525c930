// snapthread-web's LCM side against real LCM traffic, run with an observer credential: only
// what the session's server signed, and device statuses its certificate vouches for, reach
// the pages (the viewer's checks: signature, the epoch of a signed status, fresh sequence).
#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <cstring>
#include <random>

#include "auth/credential.h"
#include "auth/device_certificate.h"
#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/role_keys.h"
#include "auth/session_epoch.h"
#include "environment.h"
#include "live_feed.h"
#include "messages/channels.h"
#include "sample_messages.h"

namespace snapthread::web {
namespace {

// A device's status carrying the device key and certificate of `device` (a device KeySet).
device_status_t WithCertificate(device_status_t m, const auth::KeySet& device) {
  std::memcpy(m.device_public_key, device.device_public_key()->data(), sizeof m.device_public_key);
  std::memcpy(m.device_certificate, device.device_certificate()->data(), sizeof m.device_certificate);
  return m;
}

// A LiveFeed over udpm loopback on a unique session, run with an observer credential of
// the session's root, and an LCM to publish on it: what the feed handed on (the last text
// and the count of each kind), and the server's and a device's taggers with an epoch and
// a sequence for tagging.
class LiveFeedTest : public ::testing::Test {
 protected:
  void StartFeed(const std::string& session_prefix) {
    session_ = test_support::UniqueSession(session_prefix);
    channels_ = std::make_unique<messages::Channels>(session_);
    feed_ = std::make_unique<LiveFeed>(test_support::kLoopbackLcmUrl, session_, observer_.server_public_key(),
                                       [this](FeedKind k, Text t) {
      std::lock_guard<std::mutex> lock(mutex_);
      last_[k] = *t;
      ++published_[k];
    });
    feed_->Start();
    ASSERT_TRUE(lcm_.good());
  }
  // msg tagged by `with` in the test's epoch (untagged when null), published on channel.
  template <class Msg>
  void Publish(const std::string& channel, Msg msg, const auth::Tagger* with) {
    if (with != nullptr) {
      ASSERT_TRUE(auth::Sign(&msg, channel, epoch_, seq_.Next(), *with));
    }
    lcm_.publish(channel, &msg);
  }
  // A signed solver status, and the wait until the feed took its epoch.
  void TeachEpoch() {
    Publish(channels_->solver_status, test_support::Sample<solver_status_t>(), &server_.tagger());
    ASSERT_TRUE(test_support::WaitUntil([&] { return feed_->counts().epoch == epoch_; }, 5.0));
  }
  std::string Last(FeedKind k) {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_[k];
  }
  int Published(FeedKind k) {
    std::lock_guard<std::mutex> lock(mutex_);
    return published_[k];
  }
  int64_t Received(FeedKind k) const { return feed_->counts().received[Index(k)]; }

  const auth::SessionKey root_ = auth::SessionKey::Generate();
  const auth::KeySet server_ = auth::KeySet::FromRoot(auth::SessionKey::FromBytes(root_.data(), auth::SessionKey::kBytes));
  const auth::KeySet device_ = auth::KeySet::ForRole(root_, auth::Role::kDevice, "hand");
  // What the bridge is given: an observer credential, holding the server's public key only.
  const auth::KeySet observer_ = auth::KeySet::FromCredential(
      auth::IssueCredential(root_, auth::Role::kObserver, "", auth::kNeverExpires));
  const int64_t epoch_ = auth::NewEpoch();
  auth::AuthSequence seq_;
  std::string session_;
  std::unique_ptr<messages::Channels> channels_;
  std::mutex mutex_;
  std::map<FeedKind, std::string> last_;
  std::map<FeedKind, int> published_;
  std::unique_ptr<LiveFeed> feed_;  // after what its callback uses: stopped first
  lcm::LCM lcm_{test_support::kLoopbackLcmUrl};
};

// The feed takes the server's signed messages in the epoch of the signed status, and a
// device status its certificate vouches for; it refuses (and counts) an unsigned shape,
// one signed by another session's server and one MACed with a device key, and skips a
// force model the server did not sign without counting it.
TEST_F(LiveFeedTest, PassesOnlyWhatTheServerSigned) {
  const auth::KeySet other_server = auth::KeySet::FromRoot(auth::SessionKey::Generate());
  ASSERT_NO_FATAL_FAILURE(StartFeed("WEBFEED"));
  const messages::Channels& channels = *channels_;
  // Until the status taught the epoch, even a signed shape is refused.
  Publish(channels.shape, test_support::SampleShape(4), &server_.tagger());
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed_->counts().auth_rejected == 1; }, 5.0));
  ASSERT_NO_FATAL_FAILURE(TeachEpoch());
  Publish(channels.shape, test_support::SampleShape(4), &server_.tagger());
  Publish(channels.force_model, test_support::Sample<force_model_t>(), &server_.tagger());
  Publish(channels.device_status, WithCertificate(test_support::Sample<device_status_t>(), device_),
          device_.device_status_tagger());
  Publish(channels.force_model, test_support::Sample<force_model_t>(), nullptr);  // skipped, uncounted
  Publish(channels.shape, test_support::SampleShape(5), nullptr);
  Publish(channels.shape, test_support::SampleShape(6), &other_server.tagger());
  Publish(channels.shape, test_support::SampleShape(7), &device_.tagger());
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed_->counts().auth_rejected == 4; }, 5.0));
  ASSERT_TRUE(test_support::WaitUntil([&] { return Received(FeedKind::kDeviceStatus) == 1; }, 5.0));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const FeedCounts c = feed_->counts();
  EXPECT_EQ(c.auth_rejected, 4);
  EXPECT_EQ(c.received[Index(FeedKind::kShape)], 1);
  EXPECT_EQ(c.received[Index(FeedKind::kForceModel)], 1);
  EXPECT_EQ(c.received[Index(FeedKind::kSolverStatus)], 1);
  EXPECT_EQ(c.malformed, 0);
  const std::string last_shape = Last(FeedKind::kShape);
  EXPECT_NE(last_shape.find(R"("positions":[0,0,0,1,0.5,0,2,1,0,3,1.5,0])"), std::string::npos)
      << "the 4-node signed shape, not the refused 5-, 6- or 7-node ones: " << last_shape;
}

// Device statuses whose certificate is not the session server's: one certified by another
// root, and one whose device certified its own key. Both are refused and counted; the
// genuine device's status after them passes.
TEST_F(LiveFeedTest, RefusesDeviceStatusesTheServerDidNotCertify) {
  ASSERT_NO_FATAL_FAILURE(StartFeed("WEBCERT"));
  const messages::Channels& channels = *channels_;
  ASSERT_NO_FATAL_FAILURE(TeachEpoch());
  const auth::SessionKey other_root = auth::SessionKey::Generate();
  const auth::KeySet foreign = auth::KeySet::ForRole(other_root, auth::Role::kDevice, "hand");
  Publish(channels.device_status, WithCertificate(test_support::Sample<device_status_t>(), foreign),
          foreign.device_status_tagger());
  // Self-signed: a key pair of the forger's, certifying itself and signing the status.
  uint8_t seed[auth::kSignSeedBytes];
  std::mt19937_64 random(7);
  for (uint8_t& b : seed) b = static_cast<uint8_t>(random());
  const auth::Signer self = auth::Signer::FromSeed(seed);
  const auth::DeviceCertificateBytes self_cert =
      auth::DeviceCertificate(self, "hand", auth::kNeverExpires, self.public_key());
  auth::Tagger self_tagger;
  self_tagger.role = auth::Role::kDevice;
  self_tagger.name = "hand";
  self_tagger.signer = &self;
  device_status_t self_signed = test_support::Sample<device_status_t>();
  std::memcpy(self_signed.device_public_key, self.public_key().data(), sizeof self_signed.device_public_key);
  std::memcpy(self_signed.device_certificate, self_cert.data(), sizeof self_signed.device_certificate);
  Publish(channels.device_status, self_signed, &self_tagger);
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed_->counts().auth_rejected == 2; }, 5.0));
  EXPECT_EQ(Received(FeedKind::kDeviceStatus), 0);
  Publish(channels.device_status, WithCertificate(test_support::Sample<device_status_t>(), device_),
          device_.device_status_tagger());
  EXPECT_TRUE(test_support::WaitUntil([&] { return Received(FeedKind::kDeviceStatus) == 1; }, 5.0));
  EXPECT_EQ(feed_->counts().auth_rejected, 2);
}

// A sender without a certificate invents 100 device names (the bridge tracks 16 devices)
// before the genuine device speaks: nothing is kept for a name whose message fails its
// check, so the genuine device's status still passes, and the forged ones are refused
// and counted.
TEST_F(LiveFeedTest, ForgedDeviceIdsTakeNoPlaceOfTheGenuineDevice) {
  ASSERT_NO_FATAL_FAILURE(StartFeed("WEBIDS"));
  const messages::Channels& channels = *channels_;
  ASSERT_NO_FATAL_FAILURE(TeachEpoch());
  constexpr int kForged = 100;
  for (int i = 0; i < kForged; ++i) {
    device_status_t forged = test_support::Sample<device_status_t>();
    forged.device_id = "forged-" + std::to_string(i);
    forged.sender_role = static_cast<int8_t>(auth::Role::kDevice);
    forged.sender_name = "forged-" + std::to_string(i);
    forged.epoch = epoch_;  // read off the network: the epoch is no secret
    forged.auth_seq = seq_.Next();
    for (int b = 0; b < 64; ++b) forged.signature[b] = static_cast<uint8_t>(i + b);
    for (int b = 0; b < 64; ++b) forged.device_certificate[b] = static_cast<uint8_t>(i * b);
    Publish(channels.device_status, forged, nullptr);
  }
  // (UDP on loopback may drop a few: the count is of those the feed got.)
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed_->counts().auth_rejected >= kForged / 2; }, 5.0));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  Publish(channels.device_status, WithCertificate(test_support::Sample<device_status_t>(), device_),
          device_.device_status_tagger());
  EXPECT_TRUE(test_support::WaitUntil([&] { return Received(FeedKind::kDeviceStatus) == 1; }, 5.0))
      << "the genuine device's status was refused after " << feed_->counts().auth_rejected << " forged ones";
  const std::string last_device = Last(FeedKind::kDeviceStatus);
  EXPECT_NE(last_device.find("\"device_id\":\"sim-path\""), std::string::npos) << last_device;
}

// Force models at the update rate (a burst of 2000 here, sent as fast as LCM sends): every
// one received is vetted and counted, fewer are turned into JSON, and the newest is always
// among them once the burst ends.
TEST_F(LiveFeedTest, ABurstOfForceModelsIsCountedWholeAndPublishedUpToTheNewest) {
  ASSERT_NO_FATAL_FAILURE(StartFeed("WEBBURST"));
  ASSERT_NO_FATAL_FAILURE(TeachEpoch());
  auto send = [&](int64_t model_seq) {
    force_model_t m = test_support::Sample<force_model_t>();
    m.seq = model_seq;
    Publish(channels_->force_model, m, &server_.tagger());
  };
  // As fast as LCM sends (UDP may drop some of them: the feed counts what it got).
  constexpr int kBurst = 2000;
  for (int i = 0; i < kBurst; ++i) send(1000 + i);
  ASSERT_TRUE(test_support::WaitUntil([&] { return Received(FeedKind::kForceModel) >= 100; }, 10.0));
  // Once the burst is over, the last one, alone: it is the newest, and it is published.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  send(9999);
  EXPECT_TRUE(test_support::WaitUntil([&] { return Last(FeedKind::kForceModel).find("\"seq\":9999,") != std::string::npos; },
                                      5.0))
      << "the newest force model is published once the burst ends: " << Last(FeedKind::kForceModel);
  const int64_t received = Received(FeedKind::kForceModel);
  const int published = Published(FeedKind::kForceModel);
  EXPECT_LT(published, received) << "every force model received was turned into JSON";
  EXPECT_GE(published, 1);
}

}  // namespace
}  // namespace snapthread::web
