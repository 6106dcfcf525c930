#include "auth/pose_echo_window.h"

namespace snapthread::auth {
namespace {
std::size_t SlotOf(int64_t seq) {
  return static_cast<std::size_t>(static_cast<uint64_t>(seq) % PoseEchoWindow::kSlots);
}
}  // namespace

void PoseEchoWindow::Record(int64_t epoch, int64_t seq, int64_t utime_us) {
  Slot& s = slots_[SlotOf(seq)];
  const uint64_t v = s.version.load(std::memory_order_relaxed);
  s.version.store(v + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  s.epoch.store(epoch, std::memory_order_relaxed);
  s.seq.store(seq, std::memory_order_relaxed);
  s.utime_us.store(utime_us, std::memory_order_relaxed);
  s.version.store(v + 2, std::memory_order_release);
}

bool PoseEchoWindow::Contains(int64_t epoch, int64_t seq, int64_t utime_us) const {
  const Slot& s = slots_[SlotOf(seq)];
  // A slot being rewritten is read again; after a few tries the answer is "not sent",
  // which is the safe one (the model is dropped, the next one will do).
  for (int attempt = 0; attempt < 4; ++attempt) {
    const uint64_t v1 = s.version.load(std::memory_order_acquire);
    if (v1 & 1u) continue;
    const int64_t e = s.epoch.load(std::memory_order_relaxed);
    const int64_t q = s.seq.load(std::memory_order_relaxed);
    const int64_t t = s.utime_us.load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (s.version.load(std::memory_order_relaxed) != v1) continue;
    return v1 != 0 && e == epoch && q == seq && t == utime_us;
  }
  return false;
}

}  // namespace snapthread::auth
