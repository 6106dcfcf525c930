// When messages arrived, for tests that bound the longest silence on a channel.
#pragma once

#include <algorithm>
#include <chrono>
#include <mutex>
#include <vector>

namespace snapthread::test_support {

class ArrivalLog {
 public:
  using Clock = std::chrono::steady_clock;

  void Mark() {
    std::lock_guard<std::mutex> lock(mutex_);
    times_.push_back(Clock::now());
  }
  size_t count() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return times_.size();
  }
  // The longest gap between two arrivals from index `from` on, seconds.
  double MaxGapSince(size_t from) const {
    std::lock_guard<std::mutex> lock(mutex_);
    double gap = 0.0;
    for (size_t i = std::max<size_t>(from, 1); i < times_.size(); ++i) {
      gap = std::max(gap, std::chrono::duration<double>(times_[i] - times_[i - 1]).count());
    }
    return gap;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<Clock::time_point> times_;
};

}  // namespace snapthread::test_support
