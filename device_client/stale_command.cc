#include "stale_command.h"

namespace snapthread::device {

void StaleCommand::Set(const double force_n[3], const double torque_nm[3], int64_t now_us) {
  const uint32_t s = seq_.load(std::memory_order_relaxed);
  seq_.store(s + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  for (int k = 0; k < 3; ++k) {
    force_n_[k].store(force_n[k], std::memory_order_relaxed);
    torque_nm_[k].store(torque_nm != nullptr ? torque_nm[k] : 0.0, std::memory_order_relaxed);
  }
  stamp_us_.store(now_us, std::memory_order_relaxed);
  seq_.store(s + 2, std::memory_order_release);
}

void StaleCommand::Clear(int64_t now_us) {
  const double zero[3] = {0.0, 0.0, 0.0};
  Set(zero, zero, now_us);
}

bool StaleCommand::Output(int64_t now_us, double force_n[3], double torque_nm[3]) const {
  double f[3], t[3];
  int64_t stamp = INT64_MIN;
  bool read = false;
  for (int attempt = 0; attempt < kMaxReadAttempts && !read; ++attempt) {
    const uint32_t s0 = seq_.load(std::memory_order_acquire);
    if ((s0 & 1u) != 0) continue;
    for (int k = 0; k < 3; ++k) {
      f[k] = force_n_[k].load(std::memory_order_relaxed);
      t[k] = torque_nm_[k].load(std::memory_order_relaxed);
    }
    stamp = stamp_us_.load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    read = seq_.load(std::memory_order_relaxed) == s0;
  }
  const bool fresh = read && stamp != INT64_MIN && now_us - stamp <= limit_us_;
  for (int k = 0; k < 3; ++k) {
    force_n[k] = fresh ? f[k] : 0.0;
    torque_nm[k] = fresh ? t[k] : 0.0;
  }
  if (!fresh && stamp != INT64_MIN) stale_outputs_.fetch_add(1, std::memory_order_relaxed);
  return fresh;
}

}  // namespace snapthread::device
