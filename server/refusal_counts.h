// Every refused DEVICE_STATE and COMMAND counted by the role its sender claimed and the
// reason, published in
// solver_status_t.refusals as "role/reason=count ..." (the non-zero ones, in table
// order) and in the summary. A fixed table of atomic counters: any thread counts without
// a lock or an allocation (the gate on the receive thread, the wrong-grasp check on the
// solve thread).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>

#include "auth/freshness_filter.h"
#include "auth/key_ring.h"

namespace snapthread::server {

enum class RefusalReason : uint8_t {
  kMalformed,     // does not decode or validate
  kWrongRole,     // a role that may not speak on this channel
  kUnknownKey,    // no root gives the claimed key (another session's credential, a bad claim)
  kExpired,       // the credential's expiry has passed
  kRevoked,       // on the revocation list
  kGraceOver,     // made under the previous root after its grace period
  kBadMac,        // the MAC does not verify under the resolved key
  kWrongGrasp,    // a device's pose for a grasp that is not its own
  kForeignEpoch,  // another server session's epoch
  kReplay,        // auth_seq not above the last accepted one
  kTooMany,       // more senders or keys than the gate tracks
  kNoSuchGrasp,   // an authenticated device's pose for a grasp the scene does not have
};
inline constexpr int kRefusalCount = 12;
// "malformed", "wrong-role", ... as published.
std::string_view RefusalName(RefusalReason refusal);
// The refusal of a key ring verdict (not kAccepted) and of a freshness reason.
RefusalReason RefusalOf(auth::KeyVerdict verdict);
RefusalReason RefusalOf(auth::Reason reason);

class RefusalCounts {
 public:
  // Claimed sender_role values 0..3 (auth::Role), anything else counts as "unknown".
  static constexpr int kRoleSlots = 5;

  void Count(int8_t claimed_role, RefusalReason refusal);
  int64_t Get(int8_t claimed_role, RefusalReason refusal) const;
  int64_t Total() const;
  // "device/bad-mac=3 observer/wrong-role=1" (non-zero counts only); "" when none.
  std::string Format() const;

 private:
  static int Slot(int8_t claimed_role);
  std::array<std::array<std::atomic<int64_t>, kRefusalCount>, kRoleSlots> counts_{};
};

}  // namespace snapthread::server
