// SampleWindow: the last `capacity` samples of a quantity (tick lateness, round-trip
// latency) and their p50 / p99 / max. Storage is allocated once in the constructor, so
// Push never allocates; Compute() sorts a preallocated scratch copy. Not thread-safe by
// design: the real-time thread hands samples over an SpscRing and a non-real-time
// thread owns the window and computes the statistics.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace snapthread::realtime {

struct PercentileSummary {
  size_t count = 0;  // samples in the window
  double p50 = 0.0;
  double p99 = 0.0;
  double max = 0.0;
  double mean = 0.0;
};

class SampleWindow {
 public:
  // capacity > 0 (throws std::invalid_argument otherwise; called at start-up).
  explicit SampleWindow(size_t capacity);

  // Adds a sample, overwriting the oldest when full. No allocation.
  void Push(double value);
  void Clear();

  size_t size() const { return count_; }
  size_t capacity() const { return samples_.size(); }
  uint64_t total_pushed() const { return total_; }

  // Nearest-rank percentiles of the samples in the window; all zero when empty.
  PercentileSummary Compute() const;

 private:
  std::vector<double> samples_;
  mutable std::vector<double> scratch_;
  size_t next_ = 0;
  size_t count_ = 0;
  uint64_t total_ = 0;
};

}  // namespace snapthread::realtime
