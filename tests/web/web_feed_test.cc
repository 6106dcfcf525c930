// snapthread-web's LCM side against real LCM traffic: only what the session key signed
// reaches the pages (the viewer's checks: MAC, the epoch of a signed status, fresh sequence).
#include <chrono>
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

// Over udpm loopback (a unique session): the feed takes the key's signed messages in the
// epoch of the signed status, and refuses an unsigned shape and one of another key.
TEST(LiveFeed, PassesOnlyMessagesSignedWithTheSessionKey) {
  const auth::SessionKey key = auth::SessionKey::Generate();
  const auth::SessionKey other = auth::SessionKey::Generate();
  const std::string session = test_support::UniqueSession("WEBFEED");
  const messages::Channels channels(session);
  std::mutex mutex;
  std::string last_shape;
  LiveFeed feed(test_support::kLoopbackLcmUrl, session, key, [&](FeedKind k, Text t) {
    std::lock_guard<std::mutex> lock(mutex);
    if (k == FeedKind::kShape) last_shape = *t;
  });
  feed.Start();
  lcm::LCM lcm(test_support::kLoopbackLcmUrl);
  ASSERT_TRUE(lcm.good());
  const int64_t epoch = auth::NewEpoch();
  auth::AuthSequence seq;
  auto publish = [&](const std::string& channel, auto msg, const auth::SessionKey* with) {
    if (with != nullptr) {
      ASSERT_TRUE(auth::Sign(&msg, channel, epoch, seq.Next(), *with));
    }
    lcm.publish(channel, &msg);
  };
  // Until the status taught the epoch, even a signed shape is refused.
  publish(channels.shape, test_support::SampleShape(4), &key);
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed.counts().auth_rejected == 1; }, 5.0));
  publish(channels.solver_status, test_support::Sample<solver_status_t>(), &key);
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed.counts().epoch == epoch; }, 5.0));
  publish(channels.shape, test_support::SampleShape(4), &key);
  publish(channels.force_model, test_support::Sample<force_model_t>(), &key);
  publish(channels.device_status, test_support::Sample<device_status_t>(), &key);
  publish(channels.shape, test_support::SampleShape(5), nullptr);
  publish(channels.shape, test_support::SampleShape(6), &other);
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed.counts().auth_rejected == 3; }, 5.0));
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed.counts().received[3] == 1; }, 5.0));
  const FeedCounts c = feed.counts();
  EXPECT_EQ(c.received[Index(FeedKind::kShape)], 1);
  EXPECT_EQ(c.received[Index(FeedKind::kForceModel)], 1);
  EXPECT_EQ(c.received[Index(FeedKind::kSolverStatus)], 1);
  EXPECT_EQ(c.malformed, 0);
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_NE(last_shape.find(R"("positions":[0,0,0,1,0.5,0,2,1,0,3,1.5,0])"), std::string::npos)
      << "the 4-node signed shape, not the refused 5- or 6-node ones: " << last_shape;
}


// A sender without the key invents 100 device ids (the bridge tracks 16 devices) before
// the genuine device speaks: nothing is kept for an id whose message fails its MAC, so
// the genuine device's status still passes, and the forged ones are refused and counted.
TEST(LiveFeed, ForgedDeviceIdsTakeNoPlaceOfTheGenuineDevice) {
  const auth::SessionKey key = auth::SessionKey::Generate();
  const std::string session = test_support::UniqueSession("WEBIDS");
  const messages::Channels channels(session);
  std::mutex mutex;
  std::string last_device;
  LiveFeed feed(test_support::kLoopbackLcmUrl, session, key, [&](FeedKind k, Text t) {
    std::lock_guard<std::mutex> lock(mutex);
    if (k == FeedKind::kDeviceStatus) last_device = *t;
  });
  feed.Start();
  lcm::LCM lcm(test_support::kLoopbackLcmUrl);
  ASSERT_TRUE(lcm.good());
  const int64_t epoch = auth::NewEpoch();
  auth::AuthSequence seq;
  solver_status_t status = test_support::Sample<solver_status_t>();
  ASSERT_TRUE(auth::Sign(&status, channels.solver_status, epoch, seq.Next(), key));
  lcm.publish(channels.solver_status, &status);
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed.counts().epoch == epoch; }, 5.0));
  constexpr int kForged = 100;
  for (int i = 0; i < kForged; ++i) {
    device_status_t forged = test_support::Sample<device_status_t>();
    forged.device_id = "forged-" + std::to_string(i);
    forged.epoch = epoch;  // read off the network: the epoch is no secret
    forged.auth_seq = seq.Next();
    for (int b = 0; b < 32; ++b) forged.mac[b] = static_cast<uint8_t>(i + b);
    lcm.publish(channels.device_status, &forged);
  }
  // (UDP on loopback may drop a few: the count is of those the feed got.)
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed.counts().auth_rejected >= kForged / 2; }, 5.0));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  device_status_t genuine = test_support::Sample<device_status_t>();
  ASSERT_TRUE(auth::Sign(&genuine, channels.device_status, epoch, seq.Next(), key));
  lcm.publish(channels.device_status, &genuine);
  EXPECT_TRUE(test_support::WaitUntil([&] { return feed.counts().received[3] == 1; }, 5.0))
      << "the genuine device's status was refused after " << feed.counts().auth_rejected << " forged ones";
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_NE(last_device.find("\"device_id\":\"sim-path\""), std::string::npos) << last_device;
}

// Force models at the update rate (a burst of 2000 here, sent as fast as LCM sends): every
// one received is vetted and counted, fewer are turned into JSON, and the newest is always
// among them once the burst ends.
TEST(LiveFeed, ABurstOfForceModelsIsCountedWholeAndPublishedUpToTheNewest) {
  const auth::SessionKey key = auth::SessionKey::Generate();
  const std::string session = test_support::UniqueSession("WEBBURST");
  const messages::Channels channels(session);
  std::mutex mutex;
  int published = 0;
  std::string last_model;
  LiveFeed feed(test_support::kLoopbackLcmUrl, session, key, [&](FeedKind k, Text t) {
    std::lock_guard<std::mutex> lock(mutex);
    if (k != FeedKind::kForceModel) return;
    published++;
    last_model = *t;
  });
  feed.Start();
  lcm::LCM lcm(test_support::kLoopbackLcmUrl);
  ASSERT_TRUE(lcm.good());
  const int64_t epoch = auth::NewEpoch();
  auth::AuthSequence seq;
  solver_status_t status = test_support::Sample<solver_status_t>();
  ASSERT_TRUE(auth::Sign(&status, channels.solver_status, epoch, seq.Next(), key));
  lcm.publish(channels.solver_status, &status);
  ASSERT_TRUE(test_support::WaitUntil([&] { return feed.counts().epoch == epoch; }, 5.0));
  auto send = [&](int64_t model_seq) {
    force_model_t m = test_support::Sample<force_model_t>();
    m.seq = model_seq;
    ASSERT_TRUE(auth::Sign(&m, channels.force_model, epoch, seq.Next(), key));
    lcm.publish(channels.force_model, &m);
  };
  // As fast as LCM sends (UDP may drop some of them: the feed counts what it got).
  constexpr int kBurst = 2000;
  for (int i = 0; i < kBurst; ++i) send(1000 + i);
  ASSERT_TRUE(test_support::WaitUntil(
      [&] { return feed.counts().received[Index(FeedKind::kForceModel)] >= 100; }, 10.0));
  // Once the burst is over, the last one, alone: it is the newest, and it is published.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  send(9999);
  EXPECT_TRUE(test_support::WaitUntil([&] {
    std::lock_guard<std::mutex> lock(mutex);
    return last_model.find("\"seq\":9999,") != std::string::npos;
  }, 5.0)) << "the newest force model is published once the burst ends: " << last_model;
  const int64_t received = feed.counts().received[Index(FeedKind::kForceModel)];
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_LT(published, received) << "every force model received was turned into JSON";
  EXPECT_GE(published, 1);
}

}  // namespace
}  // namespace snapthread::web
