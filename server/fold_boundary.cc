#include "fold_boundary.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include <spdlog/spdlog.h>

#include "messages/pose_mapping.h"
#include "messages/validate.h"
#include "models/registry.h"
#include "fold_chart.h"
#include "server_messages.h"

namespace snapthread::server {
namespace {

// A search takes milliseconds for the shipped scenes; one that runs longer is abandoned.
constexpr std::chrono::seconds kSearchLimit{5};
// Look ahead kReach length scales, or this many updates of the hand's travel when that
// is longer (up to kMaxReach): far enough that the search ends long before the hand
// arrives (see the header).
constexpr double kReachUpdates = 50.0;
constexpr double kReach = 2.0, kMaxReach = 4.0;  // x the snap length scale
// A branch with a prediction is searched again when the hand's direction has turned by
// more than ~25 degrees from the one the prediction was found along.
constexpr double kTurnedCos = 0.9;

// The controls, for the log.
std::string Controls(const Vec& u) {
  std::string s;
  for (int i = 0; i < u.size(); ++i) s += (i ? ", " : "") + std::to_string(u[i]);
  return "(" + s + ")";
}

}  // namespace

FoldBoundary::FoldBoundary(const Scene& scene) : scene_(scene), search_(scene) {
  jump_threshold_ = 0.1 * SnapLengthScale(scene.params);
}

FoldBoundary::~FoldBoundary() { job_.Join(); }

void FoldBoundary::NewBranch() {
  ++branch_;
  if (spdlog::should_log(spdlog::level::debug)) spdlog::debug("fold: branch {}", branch_);
  prediction_.reset();
  clear_reach_ = 0.0;
  fold_id_ = 0;
  lambda_last_ = -1.0;
}

bool FoldBoundary::TakeSwitch(int64_t snap_fold_id, Vec* x_after, Vec* u_after) {
  if (snap_fold_id == 0 || prediction_ == nullptr || snap_fold_id != fold_id_ ||
      snap_fold_id == switched_fold_id_) {
    return false;
  }
  switched_fold_id_ = snap_fold_id;
  if (spdlog::should_log(spdlog::level::debug)) spdlog::debug("fold: the device switched at fold {}", snap_fold_id);
  *x_after = prediction_->x_after;
  *u_after = prediction_->u_after;
  NewBranch();
  have_last_ = false;
  return true;
}

void FoldBoundary::WaitForSearch() {
  while (job_.busy()) {
    Collect();
    if (job_.busy()) std::this_thread::sleep_for(std::chrono::microseconds(50));
  }
}

void FoldBoundary::Collect() {
  std::unique_ptr<Job> done;
  BackgroundJob<Job>::Failure failure;
  const auto state = job_.Poll(&done, &failure);
  if (state == BackgroundJob<Job>::State::kTimedOut || state == BackgroundJob<Job>::State::kFailed) {
    spdlog::warn("fold: a fold search {}{}", state == BackgroundJob<Job>::State::kFailed ? "failed: " : "timed out",
                 failure.message);
  }
  if (state != BackgroundJob<Job>::State::kDone) return;
  if (spdlog::should_log(spdlog::level::debug)) {
    spdlog::debug("fold: search {} for branch {} (now {}) ended: {}", done->search, done->branch, branch_,
                  done->prediction.found ? "fold at " + Controls(done->prediction.u_fold)
                                         : std::string("no fold: ") + done->prediction.why_not);
  }
  // A search for an earlier branch says nothing of this one; one that found no fold
  // leaves the prediction the branch has (see the header).
  if (done->branch != branch_) return;
  if (!done->prediction.found) {
    clear_u_ = done->u;
    clear_direction_ = done->direction;
    clear_reach_ = done->reach;
    return;
  }
  const FoldPrediction& p = done->prediction;
  const DeviceMapping& map = scene_.device;
  // The boundary in the device's pose chart (fold_chart.h).
  PoseChartFold chart;
  if (!FoldInPoseChart(scene_, p.u_fold, p.normal, p.curvature, done->u, done->orientation, &chart)) return;
  DeviceFold f{};
  for (int i = 0; i < 3; ++i) {
    f.point[i] = chart.point_m[i];
    f.normal[i] = chart.normal[i];
    f.normal_r[i] = chart.normal_r[i];
  }
  for (int i = 0; i < 4; ++i) f.q[i] = chart.q[i];
  f.curvature = chart.curvature_per_m;
  if (spdlog::should_log(spdlog::level::debug)) {
    spdlog::debug("fold: boundary at ({:.6g}, {:.6g}, {:.6g}) m, q ({:.6g}, {:.6g}, {:.6g}, {:.6g}), normal "
                  "({:.4g}, {:.4g}, {:.4g}), rotational ({:.4g}, {:.4g}, {:.4g}), curvature {:.4g} / m",
                  f.point[0], f.point[1], f.point[2], f.q[0], f.q[1], f.q[2], f.q[3], f.normal[0], f.normal[1],
                  f.normal[2], f.normal_r[0], f.normal_r[1], f.normal_r[2], f.curvature);
  }
  // The post-snap local model exactly as a force model for its state would be.
  ForceModelInputs in;
  in.mapping = &map;
  in.model = &search_.model();
  in.u = p.u_after;
  in.position_m = messages::ControlsToPosition(map, scene_.grasp_layout, p.u_after);
  in.result = &p.after;
  in.layout = &scene_.grasp_layout;
  const force_model_t post = BuildForceModel(in);
  if (post.status == force_model_t::STATUS_INVALID) return;  // no usable post-snap model
  for (int i = 0; i < 3; ++i) {
    f.post_u0[i] = post.u0[i];
    f.post_f0[i] = post.f0[i];
    f.post_torque0[i] = post.torque0[i];
    for (int j = 0; j < 3; ++j) f.post_K[i][j] = post.K[i][j];
  }
  if (fold_id_ == 0) fold_id_ = next_fold_id_++;
  prediction_ = std::make_unique<FoldPrediction>(std::move(done->prediction));
  prediction_direction_ = done->direction;
  device_fold_ = f;
}

bool FoldBoundary::StillBeforeFold(const Vec& x, const Vec& u) const {
  // The tracker calls a state change larger than its threshold a snap. Near a fold the
  // branch itself moves like sqrt(distance) ((2.54-2.55), fold_search.h), so a large
  // update step there (30 Hz on thread3d_loop: 1.5 degrees of turn) reads as a snap
  // before the fold while the state stays on the branch; dropping the prediction then
  // left the device without the fold it was about to cross. Such a state is nearer the
  // branch's last state before the fold than the state past it.
  const FoldPrediction* p = prediction_.get();
  if (p == nullptr || p->normal.size() != u.size() || x.size() != p->x_before.size() ||
      x.size() != p->x_after.size() || p->normal.dot(u - p->u_fold) >= 0.0) {
    return false;
  }
  const double to_before = (x - p->x_before).lpNorm<Eigen::Infinity>();
  const double to_after = (x - p->x_after).lpNorm<Eigen::Infinity>();
  const bool before = to_before < to_after;
  if (spdlog::should_log(spdlog::level::debug)) {
    spdlog::debug("fold: a snap at u = {} before fold {}: {:.4g} from the branch's end, {:.4g} from past it: {}",
                  Controls(u), fold_id_, to_before, to_after, before ? "still on the branch" : "a snap");
  }
  return before;
}

// The hand went past the predicted boundary and the branch goes on: that fold is not
// this branch's here. A grip's controls are periodic and a branch is not: after a whole
// turn the state differs (thread3d_loop: the loop), so a fold found one turn on lies at
// controls the branch passes again without a snap, and the device must not switch
// there. Nor is a boundary the hand has passed without a snap (a device ignoring folds,
// one whose models came late) still ahead of it.
void FoldBoundary::DropPassedPrediction(const TrackResult& r, const Vec& u) {
  if (prediction_ != nullptr && !r.snapped && r.summary.IsSolutionUsable() &&
      prediction_->normal.size() == u.size() && prediction_->normal.dot(u - prediction_->u_fold) > 0.0) {
    if (spdlog::should_log(spdlog::level::debug)) {
      spdlog::debug("fold: branch {} passed fold {} at u = {} without a snap: dropped", branch_, fold_id_,
                    Controls(u));
    }
    prediction_.reset();
    fold_id_ = 0;
  }
}

void FoldBoundary::AfterUpdate(const EquilibriumTracker& tracker, const Vec& u,
                               const Eigen::Vector4d& orientation) {
  const TrackResult& r = tracker.last();
  // A snap, a reset or a resume puts the tracker on another branch: its fold is another.
  if (r.snapped || (have_last_ && (tracker.state() - x_last_).lpNorm<Eigen::Infinity>() >
                                      10.0 * jump_threshold_)) {
    if (!StillBeforeFold(tracker.state(), u)) NewBranch();
  }
  Collect();
  DropPassedPrediction(r, u);

  // Is a fold within reach? The square-root law: lambda^2 falls linearly with the
  // distance to the fold, so distance = lambda^2 / (lambda_prev^2 - lambda^2) * |du|.
  const double lambda = r.summary.lambda_min;
  const bool usable = r.summary.IsSolutionUsable() && r.summary.status != EquilibriumStatus::kSnapping;
  if (have_last_ && usable && !job_.busy()) {
    // The hand's motion in all of its controls: a grip it turns too (fold_search.h).
    Vec d = u - u_last_;
    const double step = d.norm();
    const double scale = SnapLengthScale(scene_.params);
    const double reach = std::clamp(kReachUpdates * step, kReach * scale, kMaxReach * scale);
    bool within = r.summary.status == EquilibriumStatus::kNearFold;
    if (lambda_last_ > 0.0 && lambda > 0.0 && lambda < lambda_last_ && step > 0.0) {
      const double slope = (lambda_last_ * lambda_last_ - lambda * lambda) / step;
      within = within || lambda * lambda / slope < reach;
    }
    if (step > 0.0) d /= step;
    // The branch's fold is known along (about) this direction, or the last search found
    // none this side of half its reach: nothing new to search.
    const bool known = prediction_ != nullptr && prediction_direction_.size() == d.size() &&
                       d.dot(prediction_direction_) > kTurnedCos;
    const bool clear = clear_reach_ > 0.0 && clear_direction_.size() == d.size() &&
                       d.dot(clear_direction_) > kTurnedCos &&
                       (u - clear_u_).dot(clear_direction_) < 0.5 * clear_reach_;
    if (within && step > 0.0 && !known && !clear) {
      const Vec x = tracker.state();
      const Vec u0 = u;
      const int64_t branch = branch_;
      FoldSearchOptions options;
      options.reach = reach;
      options.tolerance = 1e-5 * scale;
      options.lateral = 0.05 * scale;
      ++searches_;
      if (spdlog::should_log(spdlog::level::debug)) {
        spdlog::debug("fold: search {} on branch {} from u = {}: lambda {:.4g} (was {:.4g}), reach {:.4g}",
                      searches_, branch_, Controls(u0), lambda, lambda_last_, reach);
      }
      job_.Start(
          [this, x, u0, d, branch, options, orientation, search = searches_] {
            auto job = std::make_unique<Job>();
            job->branch = branch;
            job->search = search;
            job->u = u0;
            job->orientation = orientation;
            job->direction = d;
            job->reach = options.reach;
            job->prediction = search_.Find(x, u0, d, options);
            return job;
          },
          kSearchLimit);
    }
  }
  if (usable) {
    if (!have_last_ || (u - u_last_).norm() > 0.0) {
      lambda_last_ = lambda;
      u_last_ = u;
    }
    x_last_ = tracker.state();
    have_last_ = true;
  }
}

void FoldBoundary::Fill(force_model_t* msg) const {
  msg->has_fold = 0;
  msg->fold_id = 0;
  msg->fold_curvature = 0.0;
  for (int i = 0; i < 3; ++i) {
    msg->fold_point[i] = msg->fold_normal[i] = msg->fold_normal_r[i] = 0.0;
    msg->post_u0[i] = msg->post_f0[i] = msg->post_torque0[i] = 0.0;
    for (int j = 0; j < 3; ++j) msg->post_K[i][j] = 0.0;
  }
  msg->fold_q[0] = 1.0;
  msg->fold_q[1] = msg->fold_q[2] = msg->fold_q[3] = 0.0;
  if (prediction_ == nullptr || msg->status == force_model_t::STATUS_INVALID ||
      msg->status == force_model_t::STATUS_SNAPPING) {
    return;
  }
  const DeviceFold& f = device_fold_;
  msg->has_fold = 1;
  msg->fold_id = fold_id_;
  msg->fold_curvature = f.curvature;
  for (int i = 0; i < 4; ++i) msg->fold_q[i] = f.q[i];
  for (int i = 0; i < 3; ++i) {
    msg->fold_point[i] = f.point[i];
    msg->fold_normal[i] = f.normal[i];
    msg->fold_normal_r[i] = f.normal_r[i];
    msg->post_u0[i] = f.post_u0[i];
    msg->post_f0[i] = f.post_f0[i];
    msg->post_torque0[i] = f.post_torque0[i];
    for (int j = 0; j < 3; ++j) msg->post_K[i][j] = f.post_K[i][j];
  }
  // The last line before the device: a prediction that fails the check is not sent.
  if (!messages::Validate(*msg, nullptr)) msg->has_fold = 0;
}

}  // namespace snapthread::server
