// Snap-ahead: a fold boundary found in the model's controls, expressed in the
// pose chart the device evaluates every servo tick (force_model_t.fold_*): position p in
// device metres and the turn r = log(R R_fold^T) of the device's orientation R from the
// orientation at the fold (the chart of the 6-DoF model, K6). The device then needs no
// scene: it checks n . (p - fold_point) + n_r . r >= (curvature / 2) |w_perp|^2
// (device_client/snap_ahead.h).
//
// With the fold function g(u) (g = 0 on the fold set, grad g = n, the unit normal from
// FoldSearch), the chart's normal is grad g carried by the chain rule through the pose
// mapping u(p, R) (messages/pose_mapping.h), at the fold:
//  * position: u = origin + s p, so dg/dp = s n_pos (s = model units per metre);
//  * grip direction (thread3d): u_d = R d_rest, scaled by rho where the search's line
//    left the sphere (the model sees u_d / |u_d| only, so n_d is tangent, n_d . u_d = 0),
//    and exp([r]x) turns d by r x d: dg/dr = rho (d x n_d) with d the unit direction;
//  * full orientation (the rod): exp([phi]x) = R, and exp([phi + J_l(phi)^-1 r]x) =
//    exp([r]x) exp([phi]x) to first order (so3.h), so dg/dr = J_l(phi)^-T n_phi.
// Scaled to a unit vector, a is the fold function divided by |(dg/dp, dg/dr)|, so the
// curvature of n . w = (kappa/2) |w_t|^2 (w_t positional, model units) becomes
// kappa s^2 / |(dg/dp, dg/dr)| per metre.
//
// R_fold: the rod's controls name the orientation (exp([phi_fold]x)). A grip direction
// names only where the grip points; the hand's roll about it is its own. The search
// starts at the hand's pose, so R_fold is the hand's orientation there turned by the
// smallest rotation that takes its grip direction to the fold's: the hand's own
// orientation at the fold when it turns without rolling (the sim-path hand). A roll psi
// about the grip picked up on the way leaves the boundary through the fold point and
// tilts it by about psi / 2 about the grip (n_r . r with r = psi d + J_l(psi d)^-1 e).
#pragma once

#include <Eigen/Core>

#include "numeric/types.h"
#include "scene/scene.h"

namespace snapthread::server {

struct PoseChartFold {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector4d q = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);  // R_fold, (w, x, y, z)
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();    // positional part
  Eigen::Vector3d normal_r = Eigen::Vector3d::Zero();  // rotational part, m/rad
  double curvature_per_m = 0.0;
};

// From a fold at controls u_fold with unit normal `normal` and curvature (1 / model unit),
// found by a search that started at controls u_start with the device at orientation
// q_start (w, x, y, z). False when the normal has no part the pose moves (or anything is
// not finite).
bool FoldInPoseChart(const Scene& scene, const Vec& u_fold, const Vec& normal, double curvature,
                     const Vec& u_start, const Eigen::Vector4d& q_start, PoseChartFold* out);

}  // namespace snapthread::server
