// A whole snap-ahead session in one process on a fake clock (issue 17): the real
// DeviceClient (servo tick, safety, SnapAhead) on the sim-path backend, and a server made
// of the server's own parts (MakeTracker, pose mapping, BuildForceModel, FoldBoundary)
// that solves the newest pose at most `server_hz` times a second. Deterministic: the
// background fold search is waited for at the update that starts it (a search takes
// milliseconds for the shipped scenes, less than a server period). Used by
// snap_ahead_test and by the chart tool (docs/snap-ahead.md).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "scene/scene.h"

namespace snapthread::snap_ahead {

struct SessionOptions {
  double server_hz = 100.0;     // equilibrium updates per second
  bool snap_ahead = true;       // server and device
  double speed_m_per_s = 0.05;  // the sim-path hand
  double duration_s = 0.0;      // 0: one pass over the scene's path there and back
};

// One servo tick as the device rendered it.
struct TickRow {
  Eigen::Vector3d position_m;
  Eigen::Vector3d force_n;
};

struct SessionResult {
  std::vector<TickRow> ticks;  // 1 kHz
  unsigned long long snap_ahead_switches = 0, snaps_felt = 0, models = 0, searches = 0;
};

SessionResult RunSession(const Scene& scene, const SessionOptions& options);

// A force step the hand felt: consecutive ticks with |dF| > step_n_per_tick; where it
// began and how large it was in all.
struct ForceJump {
  int tick = 0;                 // first tick of the step
  Eigen::Vector3d position_m;   // the hand there
  double size_n = 0.0;          // |F(end) - F(before)|
};
std::vector<ForceJump> ForceJumps(const std::vector<TickRow>& ticks, double step_n_per_tick,
                                  int settle_ticks);

// The true folds along the scene's path, device metres: the model's own continuation
// (MakeTracker, warm-started updates) in steps of `step` model units, and within the
// step that snapped again in steps of step / 1000. Each is the midpoint of the last
// control on the branch and the first past it.
std::vector<Eigen::Vector3d> TrueFolds(const Scene& scene, double step);

}  // namespace snapthread::snap_ahead
