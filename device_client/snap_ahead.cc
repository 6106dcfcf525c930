#include "snap_ahead.h"

#include <cmath>
#include <numbers>

#include <Eigen/Core>

#include "numeric/so3.h"

namespace snapthread::device {

double FoldSide(const LocalModel& model, const double position_m[3], const double orientation[4]) {
  double w[3], a = 0.0, n2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    w[i] = position_m[i] - model.fold_point_m[i];
    a += model.fold_normal[i] * w[i];
    n2 += model.fold_normal[i] * model.fold_normal[i];
  }
  // w_perp: w less its part along the positional normal (all of w when there is none).
  const double along = n2 > 0.0 ? a / n2 : 0.0;
  double perp2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double p = w[i] - along * model.fold_normal[i];
    perp2 += p * p;
  }
  if (model.has_fold_rotation) {
    // The turn from the fold's orientation, in the chart K6 uses (r = log(R R_fold^T));
    // a device that senses no orientation is at rest (the identity), as its poses say.
    static constexpr double kRest[4] = {1.0, 0.0, 0.0, 0.0};
    const Eigen::Vector3d r = so3::RotationVectorBetween(orientation != nullptr ? orientation : kRest, model.fold_q);
    // The linear boundary describes the fold near it only: a hand a quarter turn or more
    // away (where log wraps at half a turn) has not crossed it.
    if (r.squaredNorm() > 0.25 * std::numbers::pi * std::numbers::pi) return -1.0;
    for (int i = 0; i < 3; ++i) a += model.fold_normal_r[i] * r[i];
  }
  return a - 0.5 * model.fold_curvature_per_m * perp2;
}

bool PastFold(const LocalModel& model, const double position_m[3], const double orientation[4]) {
  return FoldSide(model, position_m, orientation) >= 0.0;
}

const LocalModel* SnapAhead::Select(const LocalModel* latest, const double position_m[3],
                                    const double orientation[4], int64_t next_pose_seq) {
  if (latest == nullptr) return latest;
  if (active_) {
    // A model for a pose sent after the switch comes from the new branch: render it.
    if (latest->device_seq >= switch_pose_seq_) {
      active_ = false;
    } else {
      post_.receive_us = latest->receive_us;  // the watchdog follows the server's models
      return &post_;
    }
  }
  if (!latest->has_fold || latest->fold_id == switched_fold_id_ ||
      latest->status == force_model_t::STATUS_INVALID || !PastFold(*latest, position_m, orientation)) {
    return latest;
  }
  post_ = *latest;
  post_.has_fold = false;
  // The post-snap model is a force model about post_u0 (force_model_t.post_K): the old
  // branch's 6-DoF terms do not describe the new branch.
  post_.has_wrench = false;
  post_.status = force_model_t::STATUS_SNAPPED;
  for (int i = 0; i < 3; ++i) {
    post_.u0_m[i] = latest->post_u0_m[i];
    post_.f0_n[i] = latest->post_f0_n[i];
    post_.torque0_nm[i] = latest->post_torque0_nm[i];
    for (int j = 0; j < 3; ++j) post_.K_n_per_m[i][j] = latest->post_K_n_per_m[i][j];
  }
  active_ = true;
  switched_fold_id_ = latest->fold_id;
  switch_pose_seq_ = next_pose_seq;
  switches_.fetch_add(1, std::memory_order_relaxed);
  return &post_;
}

}  // namespace snapthread::device
