// snapthread-web's LCM side against real LCM traffic: only what the session key signed
// reaches the pages (the viewer's checks: MAC, the epoch of a signed status, fresh sequence).
#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "environment.h"
#include "live_feed.h"
#include "messages/channels.h"
#include "sample_messages.h"

namespace snapthread::web {
namespace {

// A LiveFeed over udpm loopback on a unique session, and an LCM to publish on it: what
// the feed handed on (the last text and the count of each kind) and the session key's
// epoch and sequence for signing.
class LiveFeedTest : public ::testing::Test {
 protected:
  void StartFeed(const std::string& session_prefix) {
    session_ = test_support::UniqueSession(session_prefix);
    channels_ = std::make_unique<messages::Channels>(session_);
    feed_ = std::make_unique<LiveFeed>(test_support::kLoopbackLcmUrl, session_, key_, [this](FeedKind k, Text t) {
      std::lock_guard<std::mutex> lock(mutex_);
      last_[k] = *t;
      ++published_[k];
    });
    feed_->Start();
    ASSERT_TRUE(lcm_.good());
  }
  // msg signed with `with` in the test's epoch (unsigned when null), published on channel.
  template <class Msg>
  void Publish(const std::string& channel, Msg msg, const auth::SessionKey* with) {
    if (with != nullptr) {
      ASSERT_TRUE(auth::Sign(&msg, channel, epoch_, seq_.Next(), *with));
    }
    lcm_.publish(channel, &msg);
  }
  // A signed solver status, and the wait until the feed took its epoch.
  void TeachEpoch() {
    Publish(channels_->solver_status, test_support::Sample<solver_status_t>(), &key_);
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

  const auth::SessionKey key_ = auth::SessionKey::Generate();
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

// The feed takes the key's signed messages in the epoch of the signed status, and refuses
// an unsigned shape and one of another key.
TEST_F(LiveFeedTest, PassesOnlyMessagesSignedWithTheSessionKey) {
  const auth::SessionKey other = auth::SessionKey::Generate();
  ASSERT_NO_FATAL_FAILURE(StartFeed("WEBFEED"));
  const messages::Channels& channels = *channels_;
  // Until the status taught the epoch, even a signed shape is refused.
  Publish(channels.shape, test_support::SampleShape(4), &key_);
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed_->counts().auth_rejected == 1; }, 5.0));
  ASSERT_NO_FATAL_FAILURE(TeachEpoch());
  Publish(channels.shape, test_support::SampleShape(4), &key_);
  Publish(channels.force_model, test_support::Sample<force_model_t>(), &key_);
  Publish(channels.device_status, test_support::Sample<device_status_t>(), &key_);
  Publish(channels.shape, test_support::SampleShape(5), nullptr);
  Publish(channels.shape, test_support::SampleShape(6), &other);
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed_->counts().auth_rejected == 3; }, 5.0));
  ASSERT_TRUE(test_support::WaitUntil([&] { return Received(FeedKind::kDeviceStatus) == 1; }, 5.0));
  const FeedCounts c = feed_->counts();
  EXPECT_EQ(c.received[Index(FeedKind::kShape)], 1);
  EXPECT_EQ(c.received[Index(FeedKind::kForceModel)], 1);
  EXPECT_EQ(c.received[Index(FeedKind::kSolverStatus)], 1);
  EXPECT_EQ(c.malformed, 0);
  const std::string last_shape = Last(FeedKind::kShape);
  EXPECT_NE(last_shape.find(R"("positions":[0,0,0,1,0.5,0,2,1,0,3,1.5,0])"), std::string::npos)
      << "the 4-node signed shape, not the refused 5- or 6-node ones: " << last_shape;
}

// A sender without the key invents 100 device ids (the bridge tracks 16 devices) before
// the genuine device speaks: nothing is kept for an id whose message fails its MAC, so
// the genuine device's status still passes, and the forged ones are refused and counted.
TEST_F(LiveFeedTest, ForgedDeviceIdsTakeNoPlaceOfTheGenuineDevice) {
  ASSERT_NO_FATAL_FAILURE(StartFeed("WEBIDS"));
  const messages::Channels& channels = *channels_;
  ASSERT_NO_FATAL_FAILURE(TeachEpoch());
  constexpr int kForged = 100;
  for (int i = 0; i < kForged; ++i) {
    device_status_t forged = test_support::Sample<device_status_t>();
    forged.device_id = "forged-" + std::to_string(i);
    forged.epoch = epoch_;  // read off the network: the epoch is no secret
    forged.auth_seq = seq_.Next();
    for (int b = 0; b < 32; ++b) forged.mac[b] = static_cast<uint8_t>(i + b);
    Publish(channels.device_status, forged, nullptr);
  }
  // (UDP on loopback may drop a few: the count is of those the feed got.)
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed_->counts().auth_rejected >= kForged / 2; }, 5.0));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  Publish(channels.device_status, test_support::Sample<device_status_t>(), &key_);
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
    Publish(channels_->force_model, m, &key_);
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
