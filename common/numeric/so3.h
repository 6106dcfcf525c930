// Small SO(3) helpers shared by the server (a grasp's rotation-vector controls and its
// wrench, server/server_wrench.cc), the pose mapping and the device client's 6-DoF local
// model. Header-only, allocation-free (the device calls RotationVectorBetween at 1 kHz).
//
// Conventions: φ is a rotation vector, R = exp([φ]×) (Rodrigues); quaternions are
// (w, x, y, z). The left Jacobian J_l(φ) relates a world-frame ("left") perturbation to
// the rotation vector: exp([φ + δ]×) = exp([J_l(φ) δ]×) exp([φ]×) + O(δ²), with
//   J_l(φ) = I + a(θ) [φ]× + b(θ) [φ]×²,  a = (1 - cos θ)/θ²,  b = (θ - sin θ)/θ³,  θ = |φ|
// (e.g. Barfoot, "State Estimation for Robotics", (7.86)). It is singular at θ = 2π, 4π.
#pragma once

#include <cmath>
#include <numbers>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace snapthread::so3 {

inline Eigen::Matrix3d Hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

inline Eigen::Matrix3d Exp(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  if (!(angle > 1e-300)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix();
}

// The rotation vector of a unit quaternion (w, x, y, z), |φ| <= π (q and -q give the
// same φ). A zero or non-finite quaternion gives 0.
inline Eigen::Vector3d LogQuaternion(double w, double x, double y, double z) {
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  if (!(n > 0.0) || !std::isfinite(n)) return Eigen::Vector3d::Zero();
  if (w < 0.0) w = -w, x = -x, y = -y, z = -z;
  const double s = std::sqrt(x * x + y * y + z * z);
  // θ = 2 atan2(|v|, w); φ = θ v / |v| (→ 2 v / w as |v| → 0: exact to round-off).
  const double k = s > 1e-12 * n ? 2.0 * std::atan2(s, w) / s : 2.0 / w;
  return Eigen::Vector3d(k * x, k * y, k * z);
}

// exp([φ]×) as a unit quaternion (w, x, y, z) with w >= 0 where possible.
inline Eigen::Vector4d ExpQuaternion(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  const double h = 0.5 * angle;
  const double s = angle > 1e-12 ? std::sin(h) / angle : 0.5 - angle * angle / 48.0;
  return Eigen::Vector4d(std::cos(h), s * phi.x(), s * phi.y(), s * phi.z());
}

// The rotation vector of R R0ᵀ for unit quaternions q (of R) and q0 (of R0): the
// world-frame rotation that takes R0 to R, |r| <= π. No allocation.
inline Eigen::Vector3d RotationVectorBetween(const double q[4], const double q0[4]) {
  // q ⊗ conj(q0).
  const double w = q[0] * q0[0] + q[1] * q0[1] + q[2] * q0[2] + q[3] * q0[3];
  const double x = -q[0] * q0[1] + q[1] * q0[0] - q[2] * q0[3] + q[3] * q0[2];
  const double y = -q[0] * q0[2] + q[1] * q0[3] + q[2] * q0[0] - q[3] * q0[1];
  const double z = -q[0] * q0[3] - q[1] * q0[2] + q[2] * q0[1] + q[3] * q0[0];
  return LogQuaternion(w, x, y, z);
}

// The representative of exp([φ]×) nearest `near`: the rotation vectors of one rotation
// are (θ + 2πk) a for integers k (θ = |φ|, a = φ/θ). Used to keep a rotation-vector
// control continuous while a hand rolls past half a turn.
inline Eigen::Vector3d NearestRepresentative(const Eigen::Vector3d& phi, const Eigen::Vector3d& near) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  const double theta = phi.norm();
  if (!(theta > 1e-300)) {
    // The identity: 2πk b for any axis b; the nearest lies along `near`.
    const double r = near.norm();
    if (!(r > 0.0)) return Eigen::Vector3d::Zero();
    return (kTwoPi * std::round(r / kTwoPi) / r) * near;
  }
  const Eigen::Vector3d a = phi / theta;
  const double k = std::round((a.dot(near) - theta) / kTwoPi);
  return (theta + kTwoPi * k) * a;
}

// Coefficients a, b of J_l and their derivatives divided by θ, a'(θ)/θ and b'(θ)/θ
// (series below θ = 0.05, where the closed forms lose digits to cancellation).
struct LeftJacobianCoefficients {
  double a, b, da_over_theta, db_over_theta;
};
inline LeftJacobianCoefficients LeftJacobianCoeffs(double theta) {
  const double t2 = theta * theta;
  if (theta < 0.05) {
    return {0.5 - t2 / 24.0 + t2 * t2 / 720.0, 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0,
            -1.0 / 12.0 + t2 / 180.0 - t2 * t2 / 6720.0, -1.0 / 60.0 + t2 / 1260.0 - t2 * t2 / 60480.0};
  }
  const double c = std::cos(theta), s = std::sin(theta);
  const double t4 = t2 * t2;
  return {(1.0 - c) / t2, (theta - s) / (t2 * theta), (theta * s - 2.0 * (1.0 - c)) / t4,
          ((1.0 - c) * theta - 3.0 * (theta - s)) / (t4 * theta)};
}

inline Eigen::Matrix3d LeftJacobian(const Eigen::Vector3d& phi) {
  const LeftJacobianCoefficients k = LeftJacobianCoeffs(phi.norm());
  const Eigen::Matrix3d h = Hat(phi);
  return Eigen::Matrix3d::Identity() + k.a * h + k.b * h * h;
}

// D(w) = Σ_m w_m ∂J_l/∂φ_m at φ: the derivative of J_l along w.
//   ∂J_l/∂φ_m = (a'/θ) φ_m [φ]× + a [e_m]× + (b'/θ) φ_m [φ]×² + b ([e_m]×[φ]× + [φ]×[e_m]×).
inline Eigen::Matrix3d LeftJacobianDerivative(const Eigen::Vector3d& phi, const Eigen::Vector3d& w) {
  const LeftJacobianCoefficients k = LeftJacobianCoeffs(phi.norm());
  const Eigen::Matrix3d h = Hat(phi), hw = Hat(w);
  const double pw = phi.dot(w);
  return k.da_over_theta * pw * h + k.a * hw + k.db_over_theta * pw * h * h + k.b * (hw * h + h * hw);
}

// The smallest rotation taking the direction `from` to `to` (the identity for a zero or
// non-finite vector; half a turn about an axis normal to `from` when they are opposite).
// Turns a grip direction (thread3d's grasp: a direction, not a frame) into a rotation.
inline Eigen::Matrix3d SmallestRotation(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  const double nf = from.norm(), nt = to.norm();
  if (!(nf > 0.0) || !(nt > 0.0) || !from.allFinite() || !to.allFinite()) return Eigen::Matrix3d::Identity();
  const Eigen::Vector3d a = from / nf, b = to / nt;
  const Eigen::Vector3d axis = a.cross(b);
  const double s = axis.norm();
  if (s > 1e-12) return Exp((std::atan2(s, a.dot(b)) / s) * axis);
  if (a.dot(b) > 0.0) return Eigen::Matrix3d::Identity();
  const Eigen::Vector3d normal = a.cross(std::abs(a.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY());
  return Exp((std::numbers::pi / normal.norm()) * normal);
}

}  // namespace snapthread::so3
