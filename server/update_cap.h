// --max-update-hz / solver.max_update_hz: at most R equilibrium updates per
// second. The solve loop holds the newest pose of each grasp here until its slot; a pose
// that arrives meanwhile supersedes the held one of its grasp (a dropped pose).
#pragma once

#include <chrono>
#include <cstdint>
#include <vector>

#include "server_inbox.h"

namespace snapthread::server {

class UpdateCap {
 public:
  using Clock = std::chrono::steady_clock;
  // Holds poses (moved from); returns how many held ones they superseded.
  int64_t Hold(std::vector<ReceivedPose>* poses);
  // When the held poses may be solved (time_point::max() when none is held).
  Clock::time_point Wake() const;
  // The held poses into *out when their slot has come at rate_hz (<= 0: no cap).
  bool Release(double rate_hz, Clock::time_point now, std::vector<ReceivedPose>* out);

 private:
  std::vector<ReceivedPose> held_;
  Clock::time_point next_{};
};

}  // namespace snapthread::server
