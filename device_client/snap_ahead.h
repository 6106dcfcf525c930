// Snap-ahead on the device: the server sends, with a force model near a fold,
// the fold boundary (point, unit normal, curvature; device metres) and the local model of
// the equilibrium past it. Each servo tick SnapAhead checks which side of the boundary
// the hand is on; at the tick it crosses, it renders the post-snap model (the safety
// layer's slew limit still bounds the step) and every later pose carries the fold's id
// (device_state_t.snap_fold_id), so the server's next solve starts on the new branch.
//
// The boundary: w = p - point, a = n . w, w_perp = w - a n; the hand is past the fold when
//   a >= (curvature / 2) |w_perp|^2      (curvature > 0: the fold bends away from the hand).
// A fold reached by turning the grasp (thread3d_loop's grip) has a rotational part too:
// a = n . w + n_r . r with r = log(R R_fold^T), the hand's turn from the fold's
// orientation in the chart of the 6-DoF model (K6), from the quaternion the device reads
// each tick; (n, n_r) is a unit vector, and w_perp is w less its part along n. That
// boundary is linear in r, so it counts only within a quarter turn of R_fold.
// Hysteresis: a fold switches once (its id is remembered); crossing back does not switch
// back, the other branch's fold governs. The post-snap model is rendered until a model
// arrives that answers a pose sent after the switch (the server had the switch then);
// models answering earlier poses are from the old branch and are not rendered.
//
// The fold arrives checked (PrepareModel refuses a model with a bad fold, local_model.h).
// Servo thread only (Select); no allocation, no locks, no logging.
#pragma once

#include <atomic>
#include <cstdint>

#include "local_model.h"

namespace snapthread::device {

// Which side of model's fold boundary the pose (position_m, orientation (w, x, y, z);
// null: the identity) is on: a - (curvature / 2) |w_perp|^2, >= 0 past the fold; -1 a
// quarter turn or more from the fold's orientation. No allocation.
double FoldSide(const LocalModel& model, const double position_m[3], const double orientation[4]);
// FoldSide >= 0.
bool PastFold(const LocalModel& model, const double position_m[3], const double orientation[4]);

class SnapAhead {
 public:
  // The model to render this tick: `latest` (the newest received), or the post-snap model
  // after the hand crossed latest's fold. next_pose_seq: the seq the next published pose
  // will carry. Allocation-free.
  const LocalModel* Select(const LocalModel* latest, const double position_m[3],
                           const double orientation[4], int64_t next_pose_seq);

  // The fold id of the last switch (0: none), for the poses.
  int64_t snap_fold_id() const { return switched_fold_id_; }
  // Switches so far (any thread).
  uint64_t switches() const { return switches_.load(std::memory_order_relaxed); }

 private:
  LocalModel post_;
  bool active_ = false;            // rendering post_
  int64_t switched_fold_id_ = 0;
  int64_t switch_pose_seq_ = 0;    // first pose sent after the switch
  std::atomic<uint64_t> switches_{0};
};

}  // namespace snapthread::device
