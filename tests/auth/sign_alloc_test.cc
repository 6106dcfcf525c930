// Proves the per-message auth work allocates nothing after warm-up, so the device can
// sign on its 1 kHz path: the heap allocations of the thread are counted
// (tests/support/allocation_counter.h), each message type is signed
// once to warm the per-thread buffer up, then 10,000 rounds of Sign (MAC taggers and
// signers), VerifyMac, VerifySignature, the freshness filter, the pose-echo window and
// the sequence counter must allocate nothing.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "allocation_counter.h"
#include "auth/freshness_filter.h"
#include "auth/key_set.h"
#include "auth/message_gate.h"
#include "auth/message_mac.h"
#include "auth/pose_echo_window.h"
#include "auth/session_epoch.h"
#include "sample_messages.h"

namespace snapthread::auth {
namespace {

using test_support::AllocationCounter;

constexpr const char* kPoseChannel = "SNAPTHREAD_DEVICE_STATE";
constexpr const char* kModelChannel = "SNAPTHREAD_FORCE_MODEL";

TEST(AuthAllocationTest, GuardSeesTheFirstSignOfALargerMessage) {
  // The counter must be able to fail on this path: the per-thread buffer grows for a
  // message larger than any signed before on this thread.
  const KeySet server = KeySet::ForRole(SessionKey::Generate(), Role::kServer);
  thread_shape_t big = test_support::SampleShape(20000);
  long n = 0;
  {
    AllocationCounter counter;
    EXPECT_TRUE(Sign(&big, "SHAPE", 1, 1, server.tagger()));
    n = counter.mallocs();
  }
  EXPECT_GE(n, 1);
}

TEST(AuthAllocationTest, SignVerifyAndFreshnessNeverAllocateAfterWarmUp) {
  const SessionKey root = SessionKey::Generate();
  const KeySet server = KeySet::ForRole(root, Role::kServer);
  const KeySet device = KeySet::ForRole(root, Role::kDevice, "hand");
  const SessionKey& device_key = *device.mac_key();
  // The server's force models: MAC under the device's key, signed at display rate.
  Tagger model_mac = server.tagger();
  model_mac.signer = nullptr;
  model_mac.name = device.name();
  model_mac.expires_unix_s = device.expires_unix_s();
  model_mac.key_id = device.credential()->key_id;
  model_mac.mac_key = &device_key;
  Tagger model_signed = model_mac;
  model_signed.signer = server.tagger().signer;

  const int64_t epoch = NewEpoch();
  AuthSequence device_seq, server_seq;
  auto sent = std::make_unique<PoseEchoWindow>();
  FreshnessFilter pose_filter(kPoseChannel, FreshnessFilter::EpochPolicy::kFixed, epoch);
  FreshnessFilter model_filter(kModelChannel, FreshnessFilter::EpochPolicy::kFixed, epoch);
  FreshnessFilter status_filter("STATUS", FreshnessFilter::EpochPolicy::kFixed, epoch);

  device_state_t pose = test_support::Sample<device_state_t>();
  force_model_t model = test_support::Sample<force_model_t>();
  device_status_t status = test_support::Sample<device_status_t>();
  solver_status_t solver = test_support::Sample<solver_status_t>();
  // Encoded buffers the receivers check, made outside the counter (LCM's receive buffer).
  std::vector<uint8_t> pose_bytes(4096), model_bytes(4096), status_bytes(4096), solver_bytes(4096);

  // Warm-up: one of each (the per-thread buffer reaches its size).
  ASSERT_TRUE(Sign(&pose, kPoseChannel, epoch, device_seq.Next(), device.tagger()));
  ASSERT_TRUE(Sign(&model, kModelChannel, epoch, server_seq.Next(), model_signed));
  ASSERT_TRUE(Sign(&status, "STATUS", epoch, device_seq.Next(), *device.device_status_tagger()));
  ASSERT_TRUE(Sign(&solver, "SOLVER", epoch, server_seq.Next(), server.tagger()));
  const int pose_size = pose.getEncodedSize();
  const int model_size = model.getEncodedSize();

  long allocations = 0;
  int accepted_poses = 0, accepted_models = 0, verified_statuses = 0, admitted_solver = 0;
  for (int i = 0; i < 10000; ++i) {
    // Device: a new pose, MAC'd and remembered (the 1 kHz path).
    pose.seq = i + 1;
    pose.utime = 1000 * (i + 1);
    pose.position[0] = 1e-5 * i;
    {
      AllocationCounter counter;
      EXPECT_TRUE(Sign(&pose, kPoseChannel, epoch, device_seq.Next(), device.tagger()));
      sent->Record(epoch, pose.seq, pose.utime);
      allocations += counter.mallocs();
    }
    pose.encode(pose_bytes.data(), 0, pose_size);
    // Server: admits the pose, answers with a model (signed too every 16th, ~60 Hz).
    {
      AllocationCounter counter;
      if (Admit(pose_bytes.data(), static_cast<size_t>(pose_size), pose, kPoseChannel, device_key,
                &pose_filter) == Reason::kAccepted) {
        ++accepted_poses;
      }
      model.device_seq = pose.seq;
      model.device_utime = pose.utime;
      model.f0[0] = 0.001 * i;
      EXPECT_TRUE(Sign(&model, kModelChannel, epoch, server_seq.Next(), i % 16 == 0 ? model_signed : model_mac));
      allocations += counter.mallocs();
    }
    model.encode(model_bytes.data(), 0, model_size);
    if (i % 7 == 3) model_bytes[50] ^= 1;  // now and then a damaged one (bad MAC path)
    // Device: admits the model; now and then its status (MAC + its own signature), and an
    // observer's check of the status and of the server's signed solver status.
    {
      AllocationCounter counter;
      if (AdmitForceModel(model_bytes.data(), static_cast<size_t>(model_size), model,
                          kModelChannel, device_key, *sent, &model_filter) == Reason::kAccepted) {
        ++accepted_models;
      }
      if (i % 100 == 0) {
        status.ticks = i;
        EXPECT_TRUE(Sign(&status, "STATUS", epoch, device_seq.Next(), *device.device_status_tagger()));
        const int n = status.encode(status_bytes.data(), 0, static_cast<int>(status_bytes.size()));
        if (n > 0 && VerifySignature(status_bytes.data(), static_cast<size_t>(n), "STATUS",
                                     *device.device_public_key())) {
          ++verified_statuses;
        }
        solver.updates = i;
        EXPECT_TRUE(Sign(&solver, "SOLVER", epoch, server_seq.Next(), server.tagger()));
        const int m = solver.encode(solver_bytes.data(), 0, static_cast<int>(solver_bytes.size()));
        if (m > 0 && AdmitSigned(solver_bytes.data(), static_cast<size_t>(m), solver, "SOLVER",
                                 device.server_public_key(), &status_filter) == Reason::kAccepted) {
          ++admitted_solver;
        }
      }
      allocations += counter.mallocs();
    }
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(accepted_poses, 10000);
  EXPECT_EQ(verified_statuses, 100);
  EXPECT_EQ(admitted_solver, 100);
  EXPECT_EQ(model_filter.rejected(Reason::kBadMac), 10000u / 7 + (10000 % 7 > 3 ? 1 : 0));
  EXPECT_EQ(accepted_models + static_cast<int>(model_filter.rejected()), 10000);
}

}  // namespace
}  // namespace snapthread::auth
