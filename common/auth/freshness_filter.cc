#include "auth/freshness_filter.h"

#include <cstdio>
#include <utility>

namespace snapthread::auth {

const char* ReasonName(Reason reason) {
  switch (reason) {
    case Reason::kAccepted: return "accepted";
    case Reason::kBadMac: return "bad MAC";
    case Reason::kForeignEpoch: return "foreign epoch";
    case Reason::kStaleSequence: return "replayed or old sequence number";
    case Reason::kUnsentPoseEcho: return "echoes no pose this device sent";
  }
  return "unknown";
}

FreshnessFilter::FreshnessFilter(std::string name, EpochPolicy policy, int64_t epoch,
                                 int64_t log_interval_us)
    : name_(std::move(name)), policy_(policy), epoch_(epoch), log_interval_us_(log_interval_us) {}

void FreshnessFilter::SetEpoch(int64_t epoch) {
  if (epoch != epoch_.load(std::memory_order_relaxed)) last_seq_ = 0;
  epoch_.store(epoch, std::memory_order_release);
}

Reason FreshnessFilter::Check(int64_t epoch, int64_t auth_seq) const {
  const int64_t current = epoch_.load(std::memory_order_relaxed);
  if (policy_ == EpochPolicy::kFixed) {
    if (epoch == 0 || epoch != current) return Reason::kForeignEpoch;
  } else if (epoch == 0) {
    return Reason::kForeignEpoch;
  }
  // With kAdopt the floor spans epochs: this is what keeps an old session's status out.
  if (auth_seq <= last_seq_) return Reason::kStaleSequence;
  return Reason::kAccepted;
}

Reason FreshnessFilter::Admit(int64_t epoch, int64_t auth_seq) {
  const Reason reason = Check(epoch, auth_seq);
  if (reason == Reason::kAccepted) {
    last_seq_ = auth_seq;
    if (policy_ == EpochPolicy::kAdopt) epoch_.store(epoch, std::memory_order_release);
  }
  Count(reason);
  return reason;
}

void FreshnessFilter::Reject(Reason reason) {
  if (reason != Reason::kAccepted) Count(reason);
}

void FreshnessFilter::Count(Reason reason) {
  counts_[static_cast<int>(reason)].fetch_add(1, std::memory_order_relaxed);
  if (reason != Reason::kAccepted) {
    last_reason_.store(static_cast<uint8_t>(reason), std::memory_order_relaxed);
  }
}

uint64_t FreshnessFilter::rejected() const {
  uint64_t n = 0;
  for (int r = 1; r < kReasonCount; ++r) n += counts_[r].load(std::memory_order_relaxed);
  return n;
}

bool FreshnessFilter::TakeLogLine(int64_t now_us, std::string* line) {
  if (logged_once_ && now_us - last_log_us_ < log_interval_us_) return false;
  std::array<uint64_t, kReasonCount> now{};
  uint64_t fresh = 0;
  for (int r = 1; r < kReasonCount; ++r) {
    now[r] = counts_[r].load(std::memory_order_relaxed);
    fresh += now[r] - counts_at_log_[r];
  }
  if (fresh == 0) return false;
  std::string text = name_;
  text += ": ";
  text += std::to_string(fresh);
  text += " rejected";
  if (logged_once_) {
    char span[48];
    std::snprintf(span, sizeof span, " in the last %.1f s",
                  1e-6 * static_cast<double>(now_us - last_log_us_));
    text += span;
  }
  const char* sep = " (";
  for (int r = 1; r < kReasonCount; ++r) {
    const uint64_t d = now[r] - counts_at_log_[r];
    if (d == 0) continue;
    text += sep;
    text += ReasonName(static_cast<Reason>(r));
    text += ' ';
    text += std::to_string(d);
    sep = ", ";
  }
  uint64_t total = 0;
  for (int r = 1; r < kReasonCount; ++r) total += now[r];
  text += "); ";
  text += std::to_string(total);
  text += " since start; last: ";
  text += ReasonName(static_cast<Reason>(last_reason_.load(std::memory_order_relaxed)));
  counts_at_log_ = now;
  last_log_us_ = now_us;
  logged_once_ = true;
  if (line != nullptr) *line = std::move(text);
  return true;
}

}  // namespace snapthread::auth
