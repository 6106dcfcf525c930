#include "fold_chart.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "messages/pose_mapping.h"
#include "numeric/so3.h"

namespace snapthread::server {

bool FoldInPoseChart(const Scene& scene, const Vec& u_fold, const Vec& normal, double curvature,
                     const Vec& u_start, const Eigen::Vector4d& q_start, PoseChartFold* out) {
  const GraspLayout& layout = scene.grasp_layout;
  const DeviceMapping& map = scene.device;
  const int dim = std::clamp(layout.spatial_dimension, 0, 3);
  const int m = layout.NumControls();
  if (u_fold.size() != m || normal.size() != m || u_start.size() != m || !u_fold.allFinite() ||
      !normal.allFinite() || !u_start.allFinite() || !q_start.allFinite() || !std::isfinite(curvature)) {
    return false;
  }
  const double s = map.model_units_per_metre;
  PoseChartFold f;
  f.point_m = messages::ControlsToPosition(map, layout, u_fold);
  Eigen::Vector3d dp = Eigen::Vector3d::Zero(), dr = Eigen::Vector3d::Zero();
  for (int i = 0; i < dim; ++i) dp[i] = s * normal[i];
  const bool turns = (layout.grip_direction || layout.grip_rotation) && m >= dim + 3;
  if (turns && layout.grip_rotation) {
    // The rod: exp([phi]x) = R (pose_mapping.h); dg/dr = J_l(phi)^-T n_phi.
    const Eigen::Vector3d phi = u_fold.segment<3>(dim);
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(so3::LeftJacobian(phi).transpose());
    if (!lu.isInvertible()) return false;  // |phi| = 2 pi (the server keeps it below 1.25 pi)
    dr = lu.solve(Eigen::Vector3d(normal.segment<3>(dim)));
    f.q = so3::ExpQuaternion(phi);
  } else if (turns) {
    // A grip direction: d = R d_rest, the model sees u_d / rho.
    const Eigen::Vector3d u_d = u_fold.segment<3>(dim), d0 = u_start.segment<3>(dim);
    const double rho = u_d.norm();
    if (!(rho > 0.0) || !(d0.norm() > 0.0)) return false;
    const Eigen::Vector3d d = u_d / rho;
    dr = rho * d.cross(Eigen::Vector3d(normal.segment<3>(dim)));
    // R_fold: the hand's orientation at the start turned by the smallest rotation from its
    // grip direction to the fold's (see the header).
    const double qn = q_start.norm();
    const Eigen::Quaterniond q0 = qn > 0.0 ? Eigen::Quaterniond(q_start[0] / qn, q_start[1] / qn,
                                                                 q_start[2] / qn, q_start[3] / qn)
                                           : Eigen::Quaterniond::Identity();
    Eigen::Quaterniond qf(so3::SmallestRotation(d0, d) * q0.toRotationMatrix());
    qf.normalize();
    f.q = Eigen::Vector4d(qf.w(), qf.x(), qf.y(), qf.z());
  }
  const double norm = std::sqrt(dp.squaredNorm() + dr.squaredNorm());
  if (!(norm > 0.0) || !std::isfinite(norm)) return false;
  f.normal = dp / norm;
  f.normal_r = dr / norm;
  f.curvature_per_m = curvature * s * s / norm;
  if (!f.point_m.allFinite() || !f.q.allFinite() || !std::isfinite(f.curvature_per_m)) return false;
  *out = f;
  return true;
}

}  // namespace snapthread::server
