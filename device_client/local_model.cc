#include "local_model.h"

#include <cmath>

#include <Eigen/Core>

#include "messages/validate.h"
#include "numeric/so3.h"
#include "stiffness_clamp.h"

namespace snapthread::device {
namespace {

// Copies and checks a force model's fold (finite, unit normal, positive id;
// messages::Validate checked the message already) and clamps the post-snap K's stiffness
// like K. A message without a fold leaves out->has_fold false. False (with *why) when the
// fold is not usable.
bool PrepareFold(const force_model_t& msg, const SafetyLimits& limits, LocalModel* out,
                 bool* clamped, std::string* why) {
  out->has_fold = false;
  if (msg.has_fold == 0) return true;
  auto bad = [&](const char* what) {
    if (why) *why = std::string("fold: ") + what;
    return false;
  };
  if (msg.has_fold != 1 || msg.fold_id <= 0) return bad("has_fold must be 0 or 1 and fold_id > 0");
  double n2 = 0.0, r2 = 0.0, q2 = 0.0;
  bool finite = std::isfinite(msg.fold_curvature);
  for (int i = 0; i < 3; ++i) {
    n2 += msg.fold_normal[i] * msg.fold_normal[i];
    r2 += msg.fold_normal_r[i] * msg.fold_normal_r[i];
    finite = finite && std::isfinite(msg.fold_point[i]) && std::isfinite(msg.fold_normal[i]) &&
             std::isfinite(msg.fold_normal_r[i]) && std::isfinite(msg.post_u0[i]) &&
             std::isfinite(msg.post_f0[i]) && std::isfinite(msg.post_torque0[i]);
    for (int j = 0; j < 3; ++j) finite = finite && std::isfinite(msg.post_K[i][j]);
  }
  for (double q : msg.fold_q) {
    q2 += q * q;
    finite = finite && std::isfinite(q);
  }
  if (!finite) return bad("not finite");
  if (std::abs(std::sqrt(n2 + r2) - 1.0) > 1e-6) return bad("(fold_normal, fold_normal_r) is not a unit vector");
  if (std::abs(std::sqrt(q2) - 1.0) > 1e-6) return bad("fold_q is not a unit quaternion");
  bool post_clamped = false;
  if (!ClampStiffness(msg.post_K, limits, out->post_K_n_per_m, &post_clamped, why)) return false;
  *clamped = *clamped || post_clamped;
  out->has_fold = true;
  out->fold_id = msg.fold_id;
  out->fold_curvature_per_m = msg.fold_curvature;
  out->has_fold_rotation = r2 > 0.0;
  for (int i = 0; i < 4; ++i) out->fold_q[i] = msg.fold_q[i];
  for (int i = 0; i < 3; ++i) {
    out->fold_point_m[i] = msg.fold_point[i];
    out->fold_normal[i] = msg.fold_normal[i];
    out->fold_normal_r[i] = msg.fold_normal_r[i];
    out->post_u0_m[i] = msg.post_u0[i];
    out->post_f0_n[i] = msg.post_f0[i];
    out->post_torque0_nm[i] = out->has_torque ? msg.post_torque0[i] : 0.0;
  }
  return true;
}

}  // namespace

ModelVerdict PrepareModel(const force_model_t& msg, int64_t receive_us,
                          const SafetyLimits& limits, LocalModel* out, std::string* why) {
  if (!messages::Validate(msg, why)) return ModelVerdict::kRejected;
  LocalModel m;
  m.seq = msg.seq;
  m.device_seq = msg.device_seq;
  m.device_utime_us = msg.device_utime;
  m.receive_us = receive_us;
  m.status = msg.status;
  if (msg.status == force_model_t::STATUS_INVALID) {
    // No equilibrium: the message definition says render zero force. The zero model
    // still refreshes the watchdog (the server is alive) and the slew limit takes the
    // force down smoothly.
    for (int i = 0; i < 3; ++i) m.u0_m[i] = msg.u0[i];
    *out = m;
    return ModelVerdict::kInvalidStatus;
  }
  m.has_torque = msg.has_torque == 1;
  for (int i = 0; i < 3; ++i) {
    m.u0_m[i] = msg.u0[i];
    m.f0_n[i] = msg.f0[i];
    m.torque0_nm[i] = m.has_torque ? msg.torque0[i] : 0.0;
  }
  bool clamped = false;
  if (!ClampStiffness(msg.K, limits, m.K_n_per_m, &clamped, why)) return ModelVerdict::kRejected;
  if (msg.has_wrench == 1) {
    // Validate() checked q0 is a unit quaternion and K6 finite.
    m.has_wrench = true;
    const double qn = std::sqrt(msg.q0[0] * msg.q0[0] + msg.q0[1] * msg.q0[1] +
                                msg.q0[2] * msg.q0[2] + msg.q0[3] * msg.q0[3]);
    for (int i = 0; i < 4; ++i) m.q0[i] = msg.q0[i] / qn;
    bool k6_clamped = false;
    if (!ClampWrenchStiffness(msg.K6, limits, m.K6, &k6_clamped, why)) return ModelVerdict::kRejected;
    clamped = clamped || k6_clamped;
  }
  // A bad fold refuses the whole model: it never reaches the servo (snap_ahead.h
  // renders the fold).
  if (!PrepareFold(msg, limits, &m, &clamped, why)) return ModelVerdict::kRejected;
  *out = m;
  return clamped ? ModelVerdict::kStiffnessClamped : ModelVerdict::kAccepted;
}

void EvaluateLocalModel(const LocalModel& model, const double position_m[3], const double orientation[4],
                        double force_n[3], double torque_nm[3]) {
  double d[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  for (int k = 0; k < 3; ++k) d[k] = position_m[k] - model.u0_m[k];
  const bool six = model.has_wrench && orientation != nullptr;
  if (six) {
    const Eigen::Vector3d r = so3::RotationVectorBetween(orientation, model.q0);
    for (int k = 0; k < 3; ++k) d[3 + k] = r[k];
  }
  for (int i = 0; i < 3; ++i) {
    double fi = model.f0_n[i];
    double ti = model.has_torque ? model.torque0_nm[i] : 0.0;
    if (six) {
      for (int j = 0; j < 6; ++j) {
        fi += model.K6[i][j] * d[j];
        ti += model.K6[3 + i][j] * d[j];
      }
    } else {
      for (int j = 0; j < 3; ++j) fi += model.K_n_per_m[i][j] * d[j];
    }
    force_n[i] = fi;
    torque_nm[i] = ti;
  }
}

}  // namespace snapthread::device
