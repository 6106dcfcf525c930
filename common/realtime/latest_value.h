// LatestValue<T>: hands the newest value from one writer thread to one reader thread.
// A triple buffer: the writer fills its back slot and swaps it with the middle slot;
// the reader swaps the middle slot with its front slot only when the middle holds
// something newer. Both sides are wait-free (one atomic exchange each), nothing is
// allocated after construction, and the reader never sees a torn value. The writer may
// overwrite values the reader never saw: latest wins, which is what a servo loop
// wants from a force model (shared/DESIGN.md "Forces and the device's local model").
#pragma once

#include <atomic>
#include <cstdint>
#include <type_traits>

namespace snapthread::realtime {

template <class T>
class LatestValue {
  static_assert(std::is_trivially_copyable_v<T>, "LatestValue<T> needs a trivially copyable T");

 public:
  LatestValue() = default;
  LatestValue(const LatestValue&) = delete;
  LatestValue& operator=(const LatestValue&) = delete;

  // Writer thread only.
  void Write(const T& value) {
    slots_[back_] = value;
    // Publish: our back slot becomes the middle, flagged fresh; we take the old middle.
    const uint32_t old = middle_.exchange(back_ | kFreshBit, std::memory_order_acq_rel);
    back_ = old & kIndexMask;
    writes_.fetch_add(1, std::memory_order_relaxed);
  }

  // Reader thread only. Returns the newest value written so far, or nullptr if nothing
  // has been written yet. The pointer stays valid (and unchanged) until the reader's
  // next call to Latest()/Read(). Sets *fresh (if given) when the value is new since the
  // reader's previous call.
  const T* Latest(bool* fresh = nullptr) {
    bool is_new = false;
    if (middle_.load(std::memory_order_relaxed) & kFreshBit) {
      const uint32_t old = middle_.exchange(front_, std::memory_order_acq_rel);
      front_ = old & kIndexMask;
      has_value_ = true;
      is_new = true;
    }
    if (fresh) *fresh = is_new;
    return has_value_ ? &slots_[front_] : nullptr;
  }

  // Reader thread only: copies the newest value into *out; false if none was written.
  bool Read(T* out, bool* fresh = nullptr) {
    const T* p = Latest(fresh);
    if (p == nullptr) return false;
    *out = *p;
    return true;
  }

  // Any thread: how many values were written (statistics).
  uint64_t writes() const { return writes_.load(std::memory_order_relaxed); }

 private:
  static constexpr uint32_t kFreshBit = 4;
  static constexpr uint32_t kIndexMask = 3;

  T slots_[3]{};
  uint32_t back_ = 0;                    // writer-owned
  alignas(64) std::atomic<uint32_t> middle_{1};  // shared
  alignas(64) uint32_t front_ = 2;       // reader-owned
  bool has_value_ = false;               // reader-owned
  alignas(64) std::atomic<uint64_t> writes_{0};
};

}  // namespace snapthread::realtime
