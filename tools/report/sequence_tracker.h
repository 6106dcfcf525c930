// Sequence-number bookkeeping of one channel: what arrived, what is missing, what came out
// of order. A message with seq <= the highest seen so far counts as out of order (a repeat or
// a late arrival); a jump past highest + 1 is a gap of (jump - 1) missing numbers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace snapthread::report {

struct SequenceGap {
  int64_t after = 0;   // last seq before the gap
  int64_t before = 0;  // first seq after the gap
  int64_t Missing() const { return before - after - 1; }
};

class SequenceTracker {
 public:
  static constexpr size_t kMaxListedGaps = 50;

  void Add(int64_t seq);
  int64_t received() const { return received_; }
  int64_t first() const { return first_; }
  int64_t highest() const { return highest_; }
  int64_t missing() const { return missing_; }
  int64_t gap_count() const { return gap_count_; }
  int64_t out_of_order() const { return out_of_order_; }
  const std::vector<SequenceGap>& gaps() const { return gaps_; }  // first kMaxListedGaps

 private:
  int64_t received_ = 0, out_of_order_ = 0;
  int64_t first_ = 0, highest_ = 0;  // sequence numbers
  int64_t missing_ = 0, gap_count_ = 0;
  std::vector<SequenceGap> gaps_;
};

}  // namespace snapthread::report
