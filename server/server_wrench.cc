#include "server_wrench.h"

#include <cmath>

#include <Eigen/LU>

#include "numeric/so3.h"

namespace snapthread::server {

Eigen::Matrix3d ChartCurvature(const Eigen::Vector3d& phi0, const Eigen::Vector3d& grad_s) {
  const Eigen::Matrix3d jinv = so3::LeftJacobian(phi0).inverse();
  Eigen::Matrix3d t;
  for (int i = 0; i < 3; ++i) {
    // -yᵀ D(c_i) c_j with c = J⁻¹ e.
    const Eigen::RowVector3d row = -grad_s.transpose() * so3::LeftJacobianDerivative(phi0, jinv.col(i)) * jinv;
    t.row(i) = row;
  }
  // + ½ yᵀ (e_i × e_j) = -½ [y]×_ij.
  return t - 0.5 * so3::Hat(grad_s);
}

bool GraspWrenchFromControls(const Eigen::Matrix<double, 6, 1>& u, const Eigen::Matrix<double, 6, 1>& force,
                             const Mat6& stiffness, GraspWrench* out) {
  if (!u.allFinite() || !force.allFinite() || !stiffness.allFinite()) return false;
  const Eigen::Vector3d phi0 = u.tail<3>();
  const Eigen::Matrix3d jl = so3::LeftJacobian(phi0);
  // det J_l = 2 (1 - cos θ)/θ²: 4/π² at π, 0.22 at 1.25π, 0 at 2π.
  if (!(std::abs(jl.determinant()) > 1e-3)) return false;
  const Eigen::Matrix3d jinv = jl.inverse();
  const Mat6 w = -stiffness;  // W_uu
  const Eigen::Vector3d y = -(jinv.transpose() * force.tail<3>());  // Ŵ_s
  const Eigen::Matrix3d curvature = ChartCurvature(phi0, y);
  const Eigen::Matrix3d h_ss =
      jinv.transpose() * w.bottomRightCorner<3, 3>() * jinv + 0.5 * (curvature + curvature.transpose());
  const Eigen::Matrix3d h_ps = w.topRightCorner<3, 3>() * jinv;
  GraspWrench g;
  g.force = force.head<3>();
  g.torque = -y;
  g.k6.topLeftCorner<3, 3>() = -w.topLeftCorner<3, 3>();
  g.k6.topRightCorner<3, 3>() = -h_ps;
  g.k6.bottomLeftCorner<3, 3>() = -h_ps.transpose();
  g.k6.bottomRightCorner<3, 3>() = -h_ss - 0.5 * so3::Hat(g.torque);
  g.q0 = so3::ExpQuaternion(phi0);
  if (!g.k6.allFinite() || !g.torque.allFinite()) return false;
  *out = g;
  return true;
}

}  // namespace snapthread::server
