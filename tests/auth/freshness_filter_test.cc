// Freshness: epoch and strictly increasing auth_seq, epoch learning, counted reasons and
// the rate-limited log line; the pose-echo window; the receive gate that combines them.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "auth/freshness_filter.h"
#include "auth/key_set.h"
#include "auth/message_gate.h"
#include "auth/message_mac.h"
#include "auth/pose_echo_window.h"
#include "auth/session_epoch.h"
#include "sample_messages.h"

namespace snapthread::auth {
namespace {

constexpr int64_t kEpoch = 0x5eed;
constexpr int64_t kOtherEpoch = 0xbad;

TEST(FreshnessFilterTest, NothingIsAcceptedBeforeAnEpochIsKnown) {
  FreshnessFilter f("POSES");
  EXPECT_EQ(f.Admit(kEpoch, 1), Reason::kForeignEpoch);
  EXPECT_EQ(f.Admit(0, 1), Reason::kForeignEpoch);
  EXPECT_EQ(f.rejected(Reason::kForeignEpoch), 2u);
  EXPECT_EQ(f.accepted(), 0u);
}

TEST(FreshnessFilterTest, ReplayedOrOlderSequenceIsRefused) {
  FreshnessFilter f("POSES", FreshnessFilter::EpochPolicy::kFixed, kEpoch);
  EXPECT_EQ(f.Admit(kEpoch, 10), Reason::kAccepted);
  EXPECT_EQ(f.Admit(kEpoch, 10), Reason::kStaleSequence);  // the same message again
  EXPECT_EQ(f.Admit(kEpoch, 9), Reason::kStaleSequence);   // an older one (reordered)
  EXPECT_EQ(f.Admit(kEpoch, 12), Reason::kAccepted);       // gaps are fine (loss)
  EXPECT_EQ(f.Admit(kEpoch, 11), Reason::kStaleSequence);
  EXPECT_EQ(f.last_accepted_seq(), 12);
  EXPECT_EQ(f.accepted(), 2u);
  EXPECT_EQ(f.rejected(Reason::kStaleSequence), 3u);
  EXPECT_EQ(f.rejected(), 3u);
}

TEST(FreshnessFilterTest, ForeignEpochIsRefusedEvenWithAHigherSequence) {
  FreshnessFilter f("POSES", FreshnessFilter::EpochPolicy::kFixed, kEpoch);
  EXPECT_EQ(f.Admit(kEpoch, 100), Reason::kAccepted);
  EXPECT_EQ(f.Admit(kOtherEpoch, 1000), Reason::kForeignEpoch);
  EXPECT_EQ(f.last_accepted_seq(), 100);
  EXPECT_EQ(f.rejected(Reason::kForeignEpoch), 1u);
}

TEST(FreshnessFilterTest, CheckChangesNothing) {
  FreshnessFilter f("X", FreshnessFilter::EpochPolicy::kFixed, kEpoch);
  EXPECT_EQ(f.Check(kEpoch, 5), Reason::kAccepted);
  EXPECT_EQ(f.Check(kEpoch, 5), Reason::kAccepted);
  EXPECT_EQ(f.accepted() + f.rejected(), 0u);
}

TEST(FreshnessFilterTest, NewEpochForgetsTheSequenceFloor) {
  FreshnessFilter f("MODELS", FreshnessFilter::EpochPolicy::kFixed, kEpoch);
  EXPECT_EQ(f.Admit(kEpoch, 1000), Reason::kAccepted);
  f.SetEpoch(kOtherEpoch);
  EXPECT_EQ(f.Admit(kEpoch, 2000), Reason::kForeignEpoch);
  EXPECT_EQ(f.Admit(kOtherEpoch, 5), Reason::kAccepted);
  f.SetEpoch(kOtherEpoch);  // same epoch again: the floor stays
  EXPECT_EQ(f.Admit(kOtherEpoch, 5), Reason::kStaleSequence);
}

TEST(FreshnessFilterTest, AdoptLearnsEpochButNotFromAReplayedOldSession) {
  FreshnessFilter status("STATUS", FreshnessFilter::EpochPolicy::kAdopt);
  EXPECT_EQ(status.epoch(), 0);
  EXPECT_EQ(status.Admit(0, 50), Reason::kForeignEpoch);  // unsigned default
  EXPECT_EQ(status.Admit(kEpoch, 100), Reason::kAccepted);
  EXPECT_EQ(status.epoch(), kEpoch);
  // The server restarted: new epoch, sequence continues above (wall clock).
  EXPECT_EQ(status.Admit(kOtherEpoch, 200), Reason::kAccepted);
  EXPECT_EQ(status.epoch(), kOtherEpoch);
  // A replay of the first session's status cannot move the device back.
  EXPECT_EQ(status.Admit(kEpoch, 150), Reason::kStaleSequence);
  EXPECT_EQ(status.epoch(), kOtherEpoch);
}

TEST(FreshnessFilterTest, LogLineIsRateLimitedAndNamesTheReasons) {
  FreshnessFilter f("S_FORCE_MODEL", FreshnessFilter::EpochPolicy::kFixed, kEpoch, 1000000);
  std::string line;
  EXPECT_FALSE(f.TakeLogLine(0, &line));  // nothing refused yet
  f.Reject(Reason::kBadMac);
  ASSERT_TRUE(f.TakeLogLine(10, &line));  // the first refusal is reported at once
  EXPECT_EQ(line, "S_FORCE_MODEL: 1 rejected (bad MAC 1); 1 since start; last: bad MAC");
  for (int i = 0; i < 1000; ++i) f.Reject(Reason::kBadMac);
  EXPECT_EQ(f.Admit(kOtherEpoch, 1), Reason::kForeignEpoch);
  EXPECT_FALSE(f.TakeLogLine(500000, &line));  // within the interval
  ASSERT_TRUE(f.TakeLogLine(1000010, &line));
  EXPECT_EQ(line,
            "S_FORCE_MODEL: 1001 rejected in the last 1.0 s (bad MAC 1000, foreign epoch 1); "
            "1002 since start; last: foreign epoch");
  EXPECT_FALSE(f.TakeLogLine(5000000, &line));  // quiet since: no line
}

TEST(FreshnessFilterTest, ReasonNamesAreDistinct) {
  std::set<std::string> names;
  for (int r = 0; r < kReasonCount; ++r) names.insert(ReasonName(static_cast<Reason>(r)));
  EXPECT_EQ(names.size(), static_cast<size_t>(kReasonCount));
}

TEST(SessionEpochTest, EpochsAreRandomAndNonZero) {
  std::set<int64_t> seen;
  for (int i = 0; i < 1000; ++i) {
    const int64_t e = NewEpoch();
    EXPECT_NE(e, 0);
    seen.insert(e);
  }
  EXPECT_EQ(seen.size(), 1000u);
}

TEST(SessionEpochTest, SequenceStartsFromTheWallClockAndIncreases) {
  AuthSequence first;
  const int64_t a = first.Next();
  EXPECT_GT(a, 1600000000LL * 1000000000LL);  // nanoseconds since 1970, after 2020
  EXPECT_EQ(first.Next(), a + 1);
  // A sender restarted later starts above everything the first one sent.
  AuthSequence restarted;
  EXPECT_GT(restarted.Next(), first.Next());
  AuthSequence explicit_start(41);
  EXPECT_EQ(explicit_start.Next(), 42);
}

// ---- pose echo window -----------------------------------------------------------------

TEST(PoseEchoWindowTest, OnlyExactlySentPosesInTheWindow) {
  auto w = std::make_unique<PoseEchoWindow>();
  EXPECT_FALSE(w->Contains(0, 0, 0));  // an empty slot is not a sent pose
  for (int64_t s = 1; s <= 100; ++s) w->Record(kEpoch, s, 1000 * s);
  EXPECT_TRUE(w->Contains(kEpoch, 50, 50000));
  EXPECT_FALSE(w->Contains(kEpoch, 50, 50001));      // another utime
  EXPECT_FALSE(w->Contains(kOtherEpoch, 50, 50000));  // another epoch
  EXPECT_FALSE(w->Contains(kEpoch, 101, 101000));    // not sent (yet)
  // After a window's worth of newer poses the old ones are gone.
  for (int64_t s = 101; s <= 100 + static_cast<int64_t>(PoseEchoWindow::kSlots); ++s) {
    w->Record(kEpoch, s, 1000 * s);
  }
  EXPECT_FALSE(w->Contains(kEpoch, 50, 50000));
  EXPECT_TRUE(w->Contains(kEpoch, 100 + PoseEchoWindow::kSlots, 1000 * (100 + PoseEchoWindow::kSlots)));
}

TEST(PoseEchoWindowTest, ConcurrentReaderNeverSeesAPoseThatWasNotSent) {
  // The writer records (seq, utime = 3 * seq) until the reader has done its checks; the
  // reader asks for (seq, 3 * seq + 1) (never sent) and for recent true poses while
  // their slots are being overwritten.
  auto w = std::make_unique<PoseEchoWindow>();
  std::atomic<int64_t> written{0};
  std::atomic<bool> stop{false};
  std::thread writer([&] {
    for (int64_t s = 1; !stop.load(std::memory_order_relaxed); ++s) {
      w->Record(kEpoch, s, 3 * s);
      written.store(s, std::memory_order_release);
    }
  });
  long false_hits = 0, true_hits = 0;
  while (written.load(std::memory_order_acquire) < 10) std::this_thread::yield();
  for (int round = 0; round < 100000; ++round) {
    const int64_t s = written.load(std::memory_order_acquire);
    for (int64_t q = s - 5; q <= s; ++q) {
      if (w->Contains(kEpoch, q, 3 * q + 1)) ++false_hits;
      if (w->Contains(kEpoch, q, 3 * q)) ++true_hits;
    }
  }
  stop = true;
  writer.join();
  EXPECT_EQ(false_hits, 0);
  EXPECT_GT(true_hits, 0);
  // Quiescent: the last kSlots poses are all there.
  const int64_t last = written.load();
  for (int64_t q = std::max<int64_t>(1, last - static_cast<int64_t>(PoseEchoWindow::kSlots) + 1);
       q <= last; ++q) {
    ASSERT_TRUE(w->Contains(kEpoch, q, 3 * q)) << q;
  }
}

// ---- the receive gate ------------------------------------------------------------------

TEST(MessageGateTest, AdmitCountsBadMacThenFreshness) {
  const SessionKey root = SessionKey::Generate();
  const KeySet device = KeySet::ForRole(root, Role::kDevice, "hand");
  const SessionKey& key = *device.mac_key();
  FreshnessFilter f("S_DEVICE_STATE", FreshnessFilter::EpochPolicy::kFixed, kEpoch);
  device_state_t pose = test_support::Sample<device_state_t>();
  ASSERT_TRUE(Sign(&pose, "S_DEVICE_STATE", kEpoch, 7, device.tagger()));
  const auto bytes = test_support::Encode(pose);
  EXPECT_EQ(Admit(bytes.data(), bytes.size(), pose, "S_DEVICE_STATE", key, &f), Reason::kAccepted);
  EXPECT_EQ(Admit(bytes.data(), bytes.size(), pose, "S_DEVICE_STATE", key, &f),
            Reason::kStaleSequence);
  EXPECT_EQ(Admit(bytes.data(), bytes.size(), pose, "S_OTHER", key, &f), Reason::kBadMac);
  EXPECT_EQ(f.accepted(), 1u);
  EXPECT_EQ(f.rejected(Reason::kBadMac), 1u);
  EXPECT_EQ(f.rejected(Reason::kStaleSequence), 1u);
  // The root key itself, or another device's key, is not this device's key.
  EXPECT_EQ(Admit(bytes.data(), bytes.size(), pose, "S_DEVICE_STATE", root, &f), Reason::kBadMac);
  const KeySet other = KeySet::ForRole(root, Role::kDevice, "left");
  EXPECT_EQ(Admit(bytes.data(), bytes.size(), pose, "S_DEVICE_STATE", *other.mac_key(), &f), Reason::kBadMac);
  EXPECT_EQ(f.rejected(Reason::kBadMac), 3u);
}

TEST(MessageGateTest, AdmitSignedNeedsTheServerSignatureAndRole) {
  const SessionKey root = SessionKey::Generate();
  const KeySet server = KeySet::ForRole(root, Role::kServer);
  const KeySet observer = KeySet::ForRole(root, Role::kObserver);
  const KeySet op = KeySet::ForRole(root, Role::kOperator, "operator");
  FreshnessFilter f("S_SOLVER_STATUS", FreshnessFilter::EpochPolicy::kAdopt);
  solver_status_t status = test_support::Sample<solver_status_t>();
  ASSERT_TRUE(Sign(&status, "S_SOLVER_STATUS", kEpoch, 7, server.tagger()));
  auto bytes = test_support::Encode(status);
  const PublicKey& pk = observer.server_public_key();
  EXPECT_EQ(AdmitSigned(bytes.data(), bytes.size(), status, "S_SOLVER_STATUS", pk, &f), Reason::kAccepted);
  EXPECT_EQ(AdmitSigned(bytes.data(), bytes.size(), status, "S_SOLVER_STATUS", pk, &f), Reason::kStaleSequence);
  EXPECT_EQ(AdmitSigned(bytes.data(), bytes.size(), status, "S_SHAPE", pk, &f), Reason::kBadMac);
  // A status claiming the server's role but MAC'd by an operator: no signature.
  Tagger claims_server = op.tagger();
  claims_server.role = Role::kServer;
  ASSERT_TRUE(Sign(&status, "S_SOLVER_STATUS", kEpoch, 8, claims_server));
  bytes = test_support::Encode(status);
  EXPECT_EQ(AdmitSigned(bytes.data(), bytes.size(), status, "S_SOLVER_STATUS", pk, &f), Reason::kBadMac);
  // Signed by the server's key but not claiming its role.
  Tagger signed_as_device = server.tagger();
  signed_as_device.role = Role::kDevice;
  ASSERT_TRUE(Sign(&status, "S_SOLVER_STATUS", kEpoch, 9, signed_as_device));
  bytes = test_support::Encode(status);
  EXPECT_EQ(AdmitSigned(bytes.data(), bytes.size(), status, "S_SOLVER_STATUS", pk, &f), Reason::kBadMac);
  EXPECT_EQ(f.accepted(), 1u);
  EXPECT_EQ(f.rejected(Reason::kBadMac), 3u);
}

TEST(MessageGateTest, ForceModelMustEchoASentPoseAndARefusalKeepsTheFloor) {
  const SessionKey root = SessionKey::Generate();
  const KeySet device = KeySet::ForRole(root, Role::kDevice, "hand");
  const SessionKey& key = *device.mac_key();
  Tagger model_tagger;  // the server's MAC under the device's key
  model_tagger.name = "hand";
  model_tagger.key_id = device.credential()->key_id;
  model_tagger.mac_key = &key;
  auto sent = std::make_unique<PoseEchoWindow>();
  sent->Record(kEpoch, 41, 123456000);
  FreshnessFilter f("S_FORCE_MODEL", FreshnessFilter::EpochPolicy::kFixed, kEpoch);

  force_model_t unsent = test_support::Sample<force_model_t>();
  unsent.device_seq = 40;  // never sent
  ASSERT_TRUE(Sign(&unsent, "S_FORCE_MODEL", kEpoch, 500, model_tagger));
  auto bytes = test_support::Encode(unsent);
  EXPECT_EQ(AdmitForceModel(bytes.data(), bytes.size(), unsent, "S_FORCE_MODEL", key, *sent, &f),
            Reason::kUnsentPoseEcho);
  EXPECT_EQ(f.last_accepted_seq(), 0);

  force_model_t genuine = test_support::Sample<force_model_t>();  // echoes (41, 123456000)
  ASSERT_TRUE(Sign(&genuine, "S_FORCE_MODEL", kEpoch, 400, model_tagger));
  bytes = test_support::Encode(genuine);
  EXPECT_EQ(AdmitForceModel(bytes.data(), bytes.size(), genuine, "S_FORCE_MODEL", key, *sent, &f),
            Reason::kAccepted);
  EXPECT_EQ(AdmitForceModel(bytes.data(), bytes.size(), genuine, "S_FORCE_MODEL", key, *sent, &f),
            Reason::kStaleSequence);
  EXPECT_EQ(f.accepted(), 1u);
  EXPECT_EQ(f.rejected(Reason::kUnsentPoseEcho), 1u);
  EXPECT_EQ(f.rejected(Reason::kStaleSequence), 1u);
}

}  // namespace
}  // namespace snapthread::auth
