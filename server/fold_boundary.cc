#include "fold_boundary.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include <spdlog/spdlog.h>

#include "messages/pose_mapping.h"
#include "messages/validate.h"
#include "models/registry.h"
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

// The positional controls, for the log.
std::string Controls(const Vec& u, int dim) {
  std::string s;
  for (int i = 0; i < dim && i < u.size(); ++i) s += (i ? ", " : "") + std::to_string(u[i]);
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
                  done->prediction.found ? "fold at " + Controls(done->prediction.u_fold, done->direction.size())
                                         : std::string("no fold"));
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
  const double s = map.model_units_per_metre;
  const Eigen::Vector3d point = messages::ControlsToPosition(map, scene_.grasp_layout, p.u_fold);
  DeviceFold f{};
  for (int i = 0; i < 3; ++i) {
    f.point[i] = point[i];
    f.normal[i] = i < p.normal.size() ? p.normal[i] : 0.0;
  }
  f.curvature = p.curvature * s;  // 1/model unit -> 1/m
  // The post-snap local model exactly as a force model for its state would be.
  ForceModelInputs in;
  in.mapping = &map;
  in.model = &search_.model();
  in.u = p.u_after;
  in.position_m = messages::ControlsToPosition(map, scene_.grasp_layout, p.u_after);
  in.result = &p.after;
  const force_model_t post = BuildForceModel(in);
  if (post.status == force_model_t::STATUS_INVALID) return;  // no usable post-snap model
  for (int i = 0; i < 3; ++i) {
    f.post_u0[i] = post.u0[i];
    f.post_f0[i] = post.f0[i];
    for (int j = 0; j < 3; ++j) f.post_K[i][j] = post.K[i][j];
  }
  if (fold_id_ == 0) fold_id_ = next_fold_id_++;
  prediction_ = std::make_unique<FoldPrediction>(std::move(done->prediction));
  prediction_direction_ = done->direction;
  device_fold_ = f;
}

void FoldBoundary::AfterUpdate(const EquilibriumTracker& tracker, const Vec& u) {
  const TrackResult& r = tracker.last();
  // A snap, a reset or a resume puts the tracker on another branch: its fold is another.
  if (r.snapped || (have_last_ && (tracker.state() - x_last_).lpNorm<Eigen::Infinity>() >
                                      10.0 * jump_threshold_)) {
    NewBranch();
  }
  Collect();

  // Is a fold within reach? The square-root law: lambda^2 falls linearly with the
  // distance to the fold, so distance = lambda^2 / (lambda_prev^2 - lambda^2) * |du|.
  const double lambda = r.summary.lambda_min;
  const bool usable = r.summary.IsSolutionUsable() && r.summary.status != EquilibriumStatus::kSnapping;
  if (have_last_ && usable && !job_.busy()) {
    const int dim = std::min(tracker.model().SpatialDimension(), static_cast<int>(u.size()));
    Vec d = Vec::Zero(u.size());
    d.head(dim) = (u - u_last_).head(dim);
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
                       (u - clear_u_).head(dim).dot(clear_direction_.head(dim)) < 0.5 * clear_reach_;
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
                      searches_, branch_, Controls(u0, dim), lambda, lambda_last_, reach);
      }
      job_.Start(
          [this, x, u0, d, branch, options, search = searches_] {
            auto job = std::make_unique<Job>();
            job->branch = branch;
            job->search = search;
            job->u = u0;
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
    msg->fold_point[i] = msg->fold_normal[i] = msg->post_u0[i] = msg->post_f0[i] = 0.0;
    for (int j = 0; j < 3; ++j) msg->post_K[i][j] = 0.0;
  }
  if (prediction_ == nullptr || msg->status == force_model_t::STATUS_INVALID ||
      msg->status == force_model_t::STATUS_SNAPPING) {
    return;
  }
  const DeviceFold& f = device_fold_;
  msg->has_fold = 1;
  msg->fold_id = fold_id_;
  msg->fold_curvature = f.curvature;
  for (int i = 0; i < 3; ++i) {
    msg->fold_point[i] = f.point[i];
    msg->fold_normal[i] = f.normal[i];
    msg->post_u0[i] = f.post_u0[i];
    msg->post_f0[i] = f.post_f0[i];
    for (int j = 0; j < 3; ++j) msg->post_K[i][j] = f.post_K[i][j];
  }
  // The last line before the device: a prediction that fails the check is not sent.
  if (!transport::Validate(*msg, nullptr)) msg->has_fold = 0;
}

}  // namespace snapthread::server
