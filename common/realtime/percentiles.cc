#include "realtime/percentiles.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace snapthread::realtime {

SampleWindow::SampleWindow(size_t capacity) {
  if (capacity == 0) throw std::invalid_argument("SampleWindow capacity must be positive");
  samples_.assign(capacity, 0.0);
  scratch_.reserve(capacity);
}

void SampleWindow::Push(double value) {
  samples_[next_] = value;
  next_ = (next_ + 1) % samples_.size();
  if (count_ < samples_.size()) ++count_;
  ++total_;
}

void SampleWindow::Clear() {
  next_ = 0;
  count_ = 0;
}

PercentileSummary SampleWindow::Compute() const {
  PercentileSummary s;
  s.count = count_;
  if (count_ == 0) return s;
  // The window's samples are the first count_ slots until it wraps, then all of them.
  scratch_.assign(samples_.begin(), samples_.begin() + static_cast<std::ptrdiff_t>(count_));
  std::sort(scratch_.begin(), scratch_.end());
  // Nearest rank: the smallest sample with at least p of the samples at or below it.
  auto rank = [&](double p) {
    size_t r = static_cast<size_t>(std::ceil(p * static_cast<double>(count_)));
    if (r < 1) r = 1;
    if (r > count_) r = count_;
    return scratch_[r - 1];
  };
  s.p50 = rank(0.50);
  s.p99 = rank(0.99);
  s.max = scratch_.back();
  double sum = 0.0;
  for (double v : scratch_) sum += v;
  s.mean = sum / static_cast<double>(count_);
  return s;
}

}  // namespace snapthread::realtime
