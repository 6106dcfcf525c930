#include "sequence_tracker.h"

namespace snapthread::report {

void SequenceTracker::Add(int64_t seq) {
  if (received_++ == 0) {
    first_ = highest_ = seq;
    return;
  }
  if (seq <= highest_) {
    out_of_order_++;
    return;
  }
  if (seq > highest_ + 1) {
    missing_ += seq - highest_ - 1;
    gap_count_++;
    if (gaps_.size() < kMaxListedGaps) gaps_.push_back({highest_, seq});
  }
  highest_ = seq;
}

}  // namespace snapthread::report
