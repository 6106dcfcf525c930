// Snap-ahead on the solve thread: decides when a fold is within reach of the
// hand, runs the FoldSearch in the background (BackgroundJob), keeps the current fold
// prediction for the branch the tracker follows, writes it into each force model in
// device units (force_model_t.has_fold ... fold_normal_r; the pose chart, fold_chart.h) and, when a pose says the device
// switched to a fold's post-snap model (device_state_t.snap_fold_id), hands the solve
// the post-snap state so the next update starts on the new branch.
//
// Reach: near a fold lambda_min ~ sqrt(distance) along the motion (the normal form's
// square-root law, fold_search.h), so lambda^2 falls linearly; from two updates the
// distance is lambda^2 / (secant slope of lambda^2). A search starts when that estimate
// (or the tracker's near-fold status) puts a fold within `reach` of the hand: two
// length scales, or 50 updates of the hand's travel when that is longer (a fast hand,
// a slow server). It does not shrink with the update step: at 1 kHz 50 updates were
// 4 mm, 80 ms of the hand's travel at 0.05 m/s, and a server on a loaded machine can
// stall longer than that (seen here: 250 ms without a model).
//
// A branch keeps its prediction until the branch ends: a later search that finds no
// fold (along another direction, or beyond its reach) does not take it back; one that
// finds a fold replaces it; an update past the boundary that did not snap drops it (a
// grip's controls repeat every turn, the branch does not). Once a branch has a prediction, it is searched again only
// when the hand's direction has turned away from the one it was found along. A search
// that found no fold cleared its segment of the line: the next one along about the same
// direction starts when the hand has covered half of that reach.
#pragma once

#include <cstdint>
#include <memory>

#include <Eigen/Core>

#include "background_job.h"
#include "fold_search.h"
#include "scene/scene.h"
#include "snapthread/force_model_t.hpp"
#include "tracking/tracker.h"

namespace snapthread::server {

class FoldBoundary {
 public:
  explicit FoldBoundary(const Scene& scene);
  ~FoldBoundary();
  FoldBoundary(const FoldBoundary&) = delete;
  FoldBoundary& operator=(const FoldBoundary&) = delete;

  // Before an update for a pose that carries snap_fold_id: true (with the state and
  // controls to resume at) the first time the device reports the current fold's switch.
  bool TakeSwitch(int64_t snap_fold_id, Vec* x_after, Vec* u_after);
  // After each update at controls u (the device at `orientation`, (w, x, y, z): a
  // search's fold boundary is sent in the device's pose chart, fold_chart.h): notes
  // branch changes, collects a finished search and starts one when a fold is within
  // reach. The search follows all of the hand's controls: its position and the grip it
  // turns (thread3d_loop's folds are reached by turning).
  void AfterUpdate(const EquilibriumTracker& tracker, const Vec& u,
                   const Eigen::Vector4d& orientation = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0));
  // Writes the current prediction into msg (device units; has_fold = 0 when there is
  // none or msg is not a usable model). The post-snap fields come from BuildForceModel.
  void Fill(force_model_t* msg) const;

  // Blocks until a running search ends and collects it (deterministic runs: tests and
  // the chart tool; the server never waits).
  void WaitForSearch();

  int64_t searches() const { return searches_; }
  bool has_prediction() const { return prediction_ != nullptr; }

 private:
  // The prediction in device units, as force_model_t carries it.
  struct DeviceFold {
    double point[3], normal[3], curvature, post_u0[3], post_f0[3], post_K[3][3], q[4], normal_r[3],
        post_torque0[3];
  };
  struct Job {
    int64_t branch = 0;
    int64_t search = 0;  // its number (searches_), for the log
    Vec u;               // where it started
    Eigen::Vector4d orientation = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);  // the device there
    Vec direction;       // unit, all controls
    double reach = 0.0;
    FoldPrediction prediction;
  };
  void NewBranch();
  // After an update the tracker called a snap (or a large state change): true when the
  // hand is still short of the predicted boundary and the state nearer the followed
  // branch's end than the state past the fold (the branch moving fast near its fold).
  bool StillBeforeFold(const Vec& x, const Vec& u) const;
  // Takes a finished search's prediction (when it is for the current branch).
  void Collect();
  // Forgets the prediction when the hand went past its boundary without a snap.
  void DropPassedPrediction(const TrackResult& r, const Vec& u);

  Scene scene_;
  FoldSearch search_;  // used only by the running job
  BackgroundJob<Job> job_;
  std::unique_ptr<FoldPrediction> prediction_;
  Vec prediction_direction_;  // the search direction that found prediction_
  // The segment the last search of this branch found no fold on (reach 0: none).
  Vec clear_u_, clear_direction_;
  double clear_reach_ = 0.0;
  DeviceFold device_fold_{};
  int64_t branch_ = 1;         // changes at every snap, reset or switch
  int64_t fold_id_ = 0;        // of the current branch's prediction (0: none yet)
  int64_t next_fold_id_ = 1;
  int64_t switched_fold_id_ = 0;
  int64_t searches_ = 0;
  double jump_threshold_ = 0.1;
  Vec x_last_, u_last_;
  double lambda_last_ = -1.0;
  bool have_last_ = false;
};

}  // namespace snapthread::server
