// Freshness of authenticated messages from one sender (docs/security.md): only the
// current epoch, only strictly increasing auth_seq. Every refusal is counted by reason,
// and a rate-limited line of text says what was refused (the caller logs it).
//
// Threading: Admit, Reject, Check, SetEpoch and TakeLogLine are called from one thread
// (the LCM handler thread); epoch() and the counters may be read from any thread. All
// are allocation-free except TakeLogLine, which builds its text at most once per interval.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <string>

namespace snapthread::auth {

enum class Reason : uint8_t {
  kAccepted = 0,
  kBadMac,          // the MAC does not verify: no key, another key, or altered bytes
  kForeignEpoch,    // another (or no yet learned) server session
  kStaleSequence,   // auth_seq not above the last accepted one: a replay or reordering
  kUnsentPoseEcho,  // a force model answering a pose this device did not send (this epoch)
};
inline constexpr int kReasonCount = 5;

// "bad MAC", "foreign epoch", ... for logs and reports.
const char* ReasonName(Reason reason);

class FreshnessFilter {
 public:
  enum class EpochPolicy {
    // Accept only epoch(): a server checking its clients, a device checking force models
    // against the epoch it learned.
    kFixed,
    // Adopt the sender's epoch: how a device learns it from the server's authenticated
    // status. A new epoch is taken only with an auth_seq above every accepted one (a
    // restarted server's sequence continues from the wall clock), so a replayed status
    // of an old session cannot move the device back to it.
    kAdopt,
  };

  // `name` labels the log line (e.g. the channel). epoch 0 = none yet: with kFixed
  // everything is refused as a foreign epoch until SetEpoch.
  explicit FreshnessFilter(std::string name, EpochPolicy policy = EpochPolicy::kFixed,
                           int64_t epoch = 0, int64_t log_interval_us = 1000000);

  // The epoch to accept from now on. When it changes, the sequence floor is forgotten
  // (a new server session numbers afresh).
  void SetEpoch(int64_t epoch);
  int64_t epoch() const { return epoch_.load(std::memory_order_acquire); }
  int64_t last_accepted_seq() const { return last_seq_; }

  // What Admit would decide, changing nothing.
  Reason Check(int64_t epoch, int64_t auth_seq) const;
  // Check; when accepted, raises the floor to auth_seq (and, with kAdopt, takes the
  // epoch). Counts the outcome either way.
  Reason Admit(int64_t epoch, int64_t auth_seq);
  // Counts a refusal decided elsewhere (a bad MAC, a force model echoing no sent pose).
  void Reject(Reason reason);

  uint64_t accepted() const { return counts_[0].load(std::memory_order_relaxed); }
  uint64_t rejected(Reason reason) const {
    return counts_[static_cast<int>(reason)].load(std::memory_order_relaxed);
  }
  uint64_t rejected() const;  // all reasons

  // At most once per log interval, and only when something was refused since the last
  // line: true with a line like "FORCE_MODEL: 2826 rejected in the last 1.0 s (bad MAC
  // 2826); 2826 since start; last: bad MAC". The first refusal is reported at once.
  bool TakeLogLine(int64_t now_us, std::string* line);

 private:
  void Count(Reason reason);

  std::string name_;
  EpochPolicy policy_;
  std::atomic<int64_t> epoch_;
  int64_t last_seq_ = 0;  // auth_seq values must be above this (a fresh sender starts > 0)
  std::array<std::atomic<uint64_t>, kReasonCount> counts_{};
  std::atomic<uint8_t> last_reason_{0};
  int64_t log_interval_us_;
  bool logged_once_ = false;
  int64_t last_log_us_ = 0;
  std::array<uint64_t, kReasonCount> counts_at_log_{};
};

}  // namespace snapthread::auth
