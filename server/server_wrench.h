// The wrench of a grasp that holds its full orientation (the rod, GraspLayout::
// grip_rotation; docs/models-rod.md "Wrench and the 6x6 stiffness"): force and torque at
// the grasp and K6 = d(force, torque)/d(pose) from the tracker's implicit-differentiation
// stiffness, moved from the rotation-vector controls u = (p, φ) to the pose chart the
// device measures: position p and the world-frame ("left") rotation r of the grasp,
// R = exp([r]×) R0.
//
// With W(u) the energy at equilibrium (W_u = E_u, W_uu = -TrackResult::stiffness) and
// Ŵ(p, s) = W(p, φ(s)), φ(s) = log(exp([s]×) exp([φ0]×)):
//   Ŵ_s  = J⁻ᵀ W_φ                          (J = J_l(φ0), so3.h)
//   Ŵ_ss = J⁻ᵀ W_φφ J⁻¹ + Σ_k W_φk ∂²φ_k/∂s²,  Ŵ_ps = W_pφ J⁻¹
//   ∂²φ/∂s_i∂s_j = -J⁻¹ D(J⁻¹e_i) J⁻¹ e_j + ½ J⁻¹ (e_i × e_j)      (D: so3::LeftJacobianDerivative)
// The torque τ(r) = -∂/∂r' Ŵ(BCH(r', r)) with BCH(r', r) = r' + r + ½ r' × r + …, so
//   τ(r) = -(I + ½[r]×) Ŵ_s(r) + O(r²),   dτ/dr = -Ŵ_ss - ½[τ0]×,
// and F = -Ŵ_p: dF/dp = -Ŵ_pp, dF/dr = -Ŵ_ps, dτ/dp = -Ŵ_sp.
#pragma once

#include <Eigen/Core>

#include "numeric/types.h"

namespace snapthread::server {

using Mat6 = Eigen::Matrix<double, 6, 6>;

// One grasp's wrench in model units (force, energy = force x length), about u.
struct GraspWrench {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();  // world frame, about the grasp point
  // Rows f_x f_y f_z t_x t_y t_z; columns p (model length) then r (radians).
  Mat6 k6 = Mat6::Zero();
  Eigen::Vector4d q0 = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);  // exp([φ0]×), (w, x, y, z)
};

// Σ_k g_k ∂²φ_k/∂s_i∂s_j at s = 0 for g = W_φ given as y = J⁻ᵀ g (the gradient in s), not
// symmetrised (its antisymmetric part is round-off: a test checks the derivation by it).
Eigen::Matrix3d ChartCurvature(const Eigen::Vector3d& phi0, const Eigen::Vector3d& grad_s);

// From the grasp's controls u = (p, φ0), its force -W_u and stiffness -W_uu (the 6 x 6
// block of TrackResult). False (and *out untouched) when J_l(φ0) is too close to
// singular (|φ0| near 2π: the server keeps |φ0| <= 1.25π, grasp_poses.h) or anything is
// not finite.
bool GraspWrenchFromControls(const Eigen::Matrix<double, 6, 1>& u, const Eigen::Matrix<double, 6, 1>& force,
                             const Mat6& stiffness, GraspWrench* out);

}  // namespace snapthread::server
