#include "refusal_counts.h"

#include "auth/role.h"

namespace snapthread::server {
namespace {

constexpr std::array<std::string_view, kRefusalCount> kNames = {
    "malformed", "wrong-role", "unknown-key", "expired",       "revoked", "grace-over",
    "bad-mac",   "wrong-grasp", "foreign-epoch", "replay", "too-many", "no-such-grasp"};

std::string_view SlotName(int slot) {
  if (slot >= RefusalCounts::kRoleSlots - 1) return "unknown";
  return auth::RoleToString(static_cast<auth::Role>(slot));
}

}  // namespace

std::string_view RefusalName(RefusalReason refusal) { return kNames[static_cast<int>(refusal)]; }

RefusalReason RefusalOf(auth::KeyVerdict verdict) {
  switch (verdict) {
    case auth::KeyVerdict::kExpired: return RefusalReason::kExpired;
    case auth::KeyVerdict::kRevoked: return RefusalReason::kRevoked;
    case auth::KeyVerdict::kGraceOver: return RefusalReason::kGraceOver;
    case auth::KeyVerdict::kInvalidClaim: return RefusalReason::kMalformed;
    default: return RefusalReason::kUnknownKey;
  }
}

RefusalReason RefusalOf(auth::Reason reason) {
  switch (reason) {
    case auth::Reason::kBadMac: return RefusalReason::kBadMac;
    case auth::Reason::kForeignEpoch: return RefusalReason::kForeignEpoch;
    default: return RefusalReason::kReplay;
  }
}

int RefusalCounts::Slot(int8_t claimed_role) {
  return claimed_role >= 0 && claimed_role < kRoleSlots - 1 ? claimed_role : kRoleSlots - 1;
}

void RefusalCounts::Count(int8_t claimed_role, RefusalReason refusal) {
  counts_[Slot(claimed_role)][static_cast<int>(refusal)].fetch_add(1, std::memory_order_relaxed);
}

int64_t RefusalCounts::Get(int8_t claimed_role, RefusalReason refusal) const {
  return counts_[Slot(claimed_role)][static_cast<int>(refusal)].load(std::memory_order_relaxed);
}

int64_t RefusalCounts::Total() const {
  int64_t total = 0;
  for (const auto& row : counts_) {
    for (const auto& count : row) total += count.load(std::memory_order_relaxed);
  }
  return total;
}

std::string RefusalCounts::Format() const {
  std::string out;
  for (int slot = 0; slot < kRoleSlots; ++slot) {
    for (int r = 0; r < kRefusalCount; ++r) {
      const int64_t n = counts_[slot][r].load(std::memory_order_relaxed);
      if (n == 0) continue;
      if (!out.empty()) out += ' ';
      out.append(SlotName(slot)).append("/").append(kNames[r]).append("=").append(std::to_string(n));
    }
  }
  return out;
}

}  // namespace snapthread::server
