// The two freshness values every signed message carries (docs/security.md).
#pragma once

#include <atomic>
#include <cstdint>

namespace snapthread::auth {

// A server session's epoch: 64 random bits (randombytes_buf), never 0 (0 is the field's
// default and means "no epoch"). New at each server start, also when the server resumes
// a checkpoint (the saved epoch is never reused: docs/security.md "Checkpoints").
// Throws std::runtime_error only if libsodium cannot start.
int64_t NewEpoch();

// A sender's auth_seq source: strictly increasing, starting from CLOCK_REALTIME in
// nanoseconds. Starting from the wall clock (not 1) means a restarted sender continues
// above everything it sent before, so receivers that remember its last number need no
// reset, while a replay of its old messages stays below the floor. (It stays ahead as
// long as it sends fewer than 10^9 messages per second of wall-clock time.)
class AuthSequence {
 public:
  AuthSequence();
  explicit AuthSequence(int64_t last) : last_(last) {}  // next value is last + 1
  // Thread-safe and allocation-free (usable on the 1 kHz path).
  int64_t Next() { return last_.fetch_add(1, std::memory_order_relaxed) + 1; }

 private:
  std::atomic<int64_t> last_;
};

}  // namespace snapthread::auth
