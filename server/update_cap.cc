#include "update_cap.h"

#include <algorithm>

namespace snapthread::server {

int64_t UpdateCap::Hold(std::vector<ReceivedPose>* poses) {
  int64_t superseded = 0;
  for (ReceivedPose& pose : *poses) {
    auto same = std::find_if(held_.begin(), held_.end(),
                             [&](const ReceivedPose& h) { return h.state.grasp == pose.state.grasp; });
    if (same == held_.end()) {
      held_.push_back(std::move(pose));
    } else {
      ++superseded;
      *same = std::move(pose);
    }
  }
  poses->clear();
  return superseded;
}

UpdateCap::Clock::time_point UpdateCap::Wake() const {
  return held_.empty() ? Clock::time_point::max() : next_;
}

bool UpdateCap::Release(double rate_hz, Clock::time_point now, std::vector<ReceivedPose>* out) {
  if (held_.empty() || (rate_hz > 0.0 && now < next_)) return false;
  out->swap(held_);
  held_.clear();
  if (rate_hz > 0.0) {
    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate_hz));
    // Keep the phase unless the slot passed long ago.
    next_ = (now - next_ < period ? next_ : now) + period;
  }
  return true;
}

}  // namespace snapthread::server
