// The poses a device sent recently, so it can refuse a force model that answers a pose it
// never sent (docs/security.md): a model must echo the (epoch, seq, utime) of one of the
// last kSlots poses, which a replayed or re-targeted model of another session or device
// cannot do even when its MAC and sequence number pass.
//
// One writer (the thread that publishes poses) and any number of readers (the LCM
// thread); lock-free and allocation-free. Each slot is a small seqlock, so a reader never
// takes a half-written slot for a sent pose.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace snapthread::auth {

class PoseEchoWindow {
 public:
  static constexpr std::size_t kSlots = 2048;  // ~2 s of poses at 1 kHz

  // Records a published pose: the epoch it carried, its device_state_t seq and utime.
  void Record(int64_t epoch, int64_t seq, int64_t utime_us);
  // True when that exact pose is among the recorded ones still in the window.
  bool Contains(int64_t epoch, int64_t seq, int64_t utime_us) const;

 private:
  struct Slot {
    std::atomic<uint64_t> version{0};  // odd while being written
    std::atomic<int64_t> epoch{0}, seq{0}, utime_us{0};
  };
  std::array<Slot, kSlots> slots_;
};

}  // namespace snapthread::auth
