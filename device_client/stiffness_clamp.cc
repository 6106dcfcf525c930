#include "stiffness_clamp.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace snapthread::device {

bool ClampStiffness(const double K_in[3][3], const SafetyLimits& limits, double out[3][3],
                    bool* clamped, std::string* why) {
  // Stiffness S = -sym(K); clamp its eigenvalues to [0, max stable stiffness].
  Eigen::Matrix3d K;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) K(i, j) = K_in[i][j];
  }
  // Halved before adding: K + K^T overflows for entries above half the double range.
  const Eigen::Matrix3d S = -(0.5 * K + 0.5 * K.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(S);
  if (eig.info() != Eigen::Success || !eig.eigenvalues().allFinite() ||
      !eig.eigenvectors().allFinite()) {
    if (why) *why = "stiffness eigen-decomposition failed";
    return false;
  }
  Eigen::Vector3d lambda = eig.eigenvalues();
  *clamped = false;
  // Round-off tolerance: a symmetric K computed in double carries ~1e-12 relative noise.
  const double tol = 1e-9 * std::max(1.0, limits.max_stiffness_n_per_m);
  for (int i = 0; i < 3; ++i) {
    const double c = std::clamp(lambda[i], 0.0, limits.max_stiffness_n_per_m);
    if (std::abs(c - lambda[i]) > tol) *clamped = true;
    lambda[i] = c;
  }
  const Eigen::Matrix3d S_clamped =
      eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out[i][j] = -0.5 * (S_clamped(i, j) + S_clamped(j, i));
  }
  // The servo trusts K to be finite (an absurd K must never become a NaN force).
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (!std::isfinite(out[i][j])) {
        if (why) *why = "K is not finite after clamping its stiffness";
        return false;
      }
    }
  }
  return true;
}

bool ClampWrenchStiffness(const double K6_in[6][6], const SafetyLimits& limits, double out[6][6],
                          bool* clamped, std::string* why) {
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  Mat6 k;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) k(i, j) = K6_in[i][j];
  }
  const double k_max = limits.max_stiffness_n_per_m;
  const double k_rot = limits.max_torque_stiffness_nm_per_rad;
  *clamped = false;
  Mat6 result = Mat6::Zero();
  if (k_max > 0.0 && k_rot > 0.0) {
    // (u, ℓ r) with ℓ² = k_rot / k_max: K6' = T K6 T, T = diag(1, 1, 1, 1/ℓ, 1/ℓ, 1/ℓ), all
    // in N/m; -sym(K6') in [0, k_max] <=> the force block in [0, k_max] N/m and the
    // torque block in [0, k_rot] N m/rad, with a coupling that keeps the whole PSD.
    const double ell = std::sqrt(k_rot / k_max);
    Eigen::Matrix<double, 6, 1> t;
    t << 1.0, 1.0, 1.0, 1.0 / ell, 1.0 / ell, 1.0 / ell;
    const Mat6 kp = t.asDiagonal() * k * t.asDiagonal();
    const Mat6 sym = -(0.5 * kp + 0.5 * kp.transpose());
    Mat6 skew = 0.5 * kp - 0.5 * kp.transpose();
    Eigen::SelfAdjointEigenSolver<Mat6> eig(sym);
    if (eig.info() != Eigen::Success || !eig.eigenvalues().allFinite() || !eig.eigenvectors().allFinite()) {
      if (why) *why = "K6 stiffness eigen-decomposition failed";
      return false;
    }
    Eigen::Matrix<double, 6, 1> lambda = eig.eigenvalues();
    const double tol = 1e-9 * std::max(1.0, k_max);
    for (int i = 0; i < 6; ++i) {
      const double c = std::clamp(lambda[i], 0.0, k_max);
      if (std::abs(c - lambda[i]) > tol) *clamped = true;
      lambda[i] = c;
    }
    // -½[τ0]× has Frobenius norm |τ0| / √2; in K6' it is divided by ℓ².
    const double skew_max = limits.max_torque_nm / (std::sqrt(2.0) * ell * ell);
    const double skew_norm = skew.norm();
    if (!std::isfinite(skew_norm)) {
      if (why) *why = "K6 is not finite";
      return false;
    }
    if (skew_norm > skew_max * (1.0 + 1e-9)) {
      skew *= skew_max / skew_norm;
      *clamped = true;
    }
    const Mat6 s = eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
    const Mat6 kc = -(0.5 * s + 0.5 * s.transpose()) + skew;
    result = t.cwiseInverse().asDiagonal() * kc * t.cwiseInverse().asDiagonal();
  } else {
    double k3[3][3], c3[3][3];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) k3[i][j] = K6_in[i][j];
    }
    if (!ClampStiffness(k3, limits, c3, clamped, why)) return false;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) result(i, j) = c3[i][j];
    }
    if (!(k.bottomRows<3>().isZero(0.0) && k.topRightCorner<3, 3>().isZero(0.0))) *clamped = true;
  }
  if (!result.allFinite()) {
    if (why) *why = "K6 is not finite after clamping its stiffness";
    return false;
  }
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) out[i][j] = result(i, j);
  }
  return true;
}

}  // namespace snapthread::device
