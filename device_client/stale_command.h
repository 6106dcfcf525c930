// StaleCommand: a backend's last force/torque command and when it was given
// (CLOCK_MONOTONIC microseconds), handed from the servo thread to whatever renders it (a
// device's scheduler callback, a simulated device's render thread or physics). Output
// renders zero once the command is older than the limit: if the servo thread stalls, the
// device stops pushing within limit_us instead of holding the last force forever.
//
// A sequence lock over atomics: Set is wait-free for the one writer (the servo thread,
// or the thread that closes the device after the servo stopped); Output may be called
// from any number of reader threads, never allocates and never waits for the writer: a
// read that keeps colliding with writes (a writer stopped in the middle of one) renders
// zero, which is the safe side.
#pragma once

#include <atomic>
#include <cstdint>

namespace snapthread::device {

class StaleCommand {
 public:
  // 5 ms: five servo ticks at 1 kHz. Long enough for a tick's usual lateness (p99 well
  // under 1 ms here), short enough that a stalled servo cannot push for long.
  static constexpr int64_t kDefaultLimitUs = 5000;

  explicit StaleCommand(int64_t limit_us = kDefaultLimitUs) : limit_us_(limit_us) {}
  StaleCommand(const StaleCommand&) = delete;
  StaleCommand& operator=(const StaleCommand&) = delete;

  // The command given at now_us (writer thread). torque_nm may be null (zero torque).
  void Set(const double force_n[3], const double torque_nm[3], int64_t now_us);
  // Zero force and torque, stamped now_us (the device is being closed).
  void Clear(int64_t now_us);

  // What to render at now_us: the last command while it is at most limit_us old (a
  // command stamped after now_us, from a clock read a moment later, counts as fresh),
  // else zero. True when the command was fresh. Any thread; allocation-free.
  bool Output(int64_t now_us, double force_n[3], double torque_nm[3]) const;

  // The time stamp of the last command (INT64_MIN before the first); any thread.
  int64_t last_command_us() const { return stamp_us_.load(std::memory_order_acquire); }
  int64_t limit_us() const { return limit_us_; }
  // Outputs zeroed because the command was stale or could not be read; any thread.
  uint64_t stale_outputs() const { return stale_outputs_.load(std::memory_order_relaxed); }

 private:
  static constexpr int kMaxReadAttempts = 64;

  const int64_t limit_us_;
  std::atomic<uint32_t> seq_{0};  // odd while a write is in progress
  std::atomic<double> force_n_[3] = {0.0, 0.0, 0.0};
  std::atomic<double> torque_nm_[3] = {0.0, 0.0, 0.0};
  std::atomic<int64_t> stamp_us_{INT64_MIN};
  mutable std::atomic<uint64_t> stale_outputs_{0};
};

}  // namespace snapthread::device
