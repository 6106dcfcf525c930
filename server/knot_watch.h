// The knot type of the current shape, computed a few times a second on a
// background thread so the solve thread never waits for it: each tick the solve thread
// collects a finished identification and, when the last one has ended and the period has
// passed, hands a copy of the chain's nodes to a new one. Curves only (thread3d, rod,
// curve2d: a planar curve that does not cross itself is the unknot); for zeeman and cusp
// the knot stays "" (not computed).
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "background_job.h"
#include "topology/identify_knot.h"
#include "tracking/tracker.h"
#include "scene/scene.h"

namespace snapthread::server {

class KnotWatch {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr double kRateHz = 4.0;
  // An identification takes about a millisecond at n = 1000 (tests/topology_test.cc); one
  // still running after this is abandoned and reported as not computed.
  static constexpr std::chrono::seconds kLimit{2};

  // Solve thread, once per loop. Never blocks on the identification.
  void Tick(Clock::time_point now, const Scene& scene, const EquilibriumTracker& tracker);
  // A new scene or a reset: forget the last answer; one still running is dropped.
  void Reset();

  const std::string& name() const { return name_; }  // "" = not computed yet
  int32_t determinant() const { return determinant_; }  // 0 = not computed
  int64_t identified() const { return identified_; }  // answers collected so far

 private:
  struct Answer {
    int64_t generation = 0;
    topology::KnotInfo info;
  };
  BackgroundJob<Answer> job_;
  int64_t generation_ = 0;
  Clock::time_point next_{};
  std::string name_;
  int32_t determinant_ = 0;
  int64_t identified_ = 0;
};

}  // namespace snapthread::server
