// A whole snap-ahead session in one process on a fake clock: the real
// DeviceClient (servo tick, safety, SnapAhead) on the sim-path backend, and a server made
// of the server's own parts (MakeTracker, pose mapping, BuildForceModel, FoldBoundary)
// that solves the newest pose at most `server_hz` times a second. Deterministic: the
// background fold search is waited for at the update that starts it (a search takes
// milliseconds for the shipped scenes, less than a server period). Used by
// snap_ahead_test and by the chart tool (docs/snap-ahead.md).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "numeric/types.h"
#include "scene/scene.h"

namespace snapthread::snap_ahead {

struct SessionOptions {
  double server_hz = 100.0;     // equilibrium updates per second
  bool snap_ahead = true;       // server and device
  double speed_m_per_s = 0.05;  // the sim-path hand
  double duration_s = 0.0;      // 0: one pass over the scene's path (it goes there and back)
};

// One servo tick as the device rendered it.
struct TickRow {
  Eigen::Vector3d position_m;
  Eigen::Vector4d orientation;  // (w, x, y, z), as the device read it
  Eigen::Vector3d force_n;
  Eigen::Vector3d torque_nm;    // on the grip (the sim-path hand renders torque)
};

struct SessionResult {
  std::vector<TickRow> ticks;  // 1 kHz
  unsigned long long snap_ahead_switches = 0, snaps_felt = 0, models = 0, searches = 0;
};

SessionResult RunSession(const Scene& scene, const SessionOptions& options);

// A step the hand felt: consecutive ticks with |dF| > step_n_per_tick or |dtau| >
// step_nm_per_tick (a grip's torque; <= 0: force only); where it began and how large
// it was in all.
struct ForceJump {
  int tick = 0;                 // first tick of the step
  Eigen::Vector3d position_m;   // the hand there
  double size_n = 0.0;          // |F(end) - F(before)|
  double size_nm = 0.0;         // |tau(end) - tau(before)|
};
std::vector<ForceJump> ForceJumps(const std::vector<TickRow>& ticks, double step_n_per_tick,
                                  double step_nm_per_tick, int settle_ticks);

// The true folds along the scene's path, in the model's controls (a grip direction
// scaled back to a unit vector): the model's own continuation (MakeTracker,
// warm-started updates) in steps of `step` (controls: model units, and a grip
// direction's chord), and within the step that snapped again in steps of step / 1000.
// Each is the midpoint of the last control on the branch and the first past it.
std::vector<Vec> TrueFolds(const Scene& scene, double step);

// The controls of a tick's pose (messages::PoseToControls, as the server maps it).
Vec TickControls(const Scene& scene, const TickRow& tick);

// Where a force jump began against a fold, in servo ticks of travel (> 0: late): the
// offset of the jump's pose from the fold in the controls, along the hand's motion at
// that tick, over the motion of one tick. A hand that turns its grip (thread3d_loop)
// travels in the grip's controls: a tick of travel is then a tick of turning.
double SnapErrorTicks(const Scene& scene, const std::vector<TickRow>& ticks, const ForceJump& jump,
                      const Vec& fold);

}  // namespace snapthread::snap_ahead
