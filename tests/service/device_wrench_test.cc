// The device's 6-DoF local model (issue 14 item 3; device_client/safety.h): the K6 clamp,
// the torque guards (bound, slew limit, zero on a bad model), a 3-DoF device that renders
// the force with its rotation coupling and no torque, and the scripted path's roll.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Eigenvalues>

#include "numeric/so3.h"
#include "safety.h"
#include "scripted_path.h"
#include "sim_path_device.h"

namespace snapthread::device {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int64_t kTickUs = 1000;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// The limits the tests below are written for, spelled out so that a change of the
// defaults does not change the tests.
SafetyLimits Limits() {
  return {.max_force_n = 3.0, .max_stiffness_n_per_m = 800.0, .max_force_rate_n_per_s = 1000.0,
          .model_timeout_s = 0.050, .fade_time_s = 0.100, .workspace_radius_m = 0.08,
          .max_torque_nm = 0.05, .max_torque_rate_nm_per_s = 20.0,
          .max_torque_stiffness_nm_per_rad = 0.1, .tick_period_s = 0.001};
}

// A rod-like wrench model: a spring in position, a torsion spring in rotation with the
// -½[τ0]× of a torque τ0, a small coupling.
force_model_t WrenchModel(const Eigen::Vector3d& torque0, double k_rot = 0.01) {
  force_model_t m{};
  m.seq = 1;
  m.status = force_model_t::STATUS_REGULAR;
  m.f0[0] = 0.5;
  m.has_torque = 1;
  m.has_wrench = 1;
  const Eigen::Vector4d q0 = so3::ExpQuaternion(Eigen::Vector3d(0.3, -0.2, 1.0));
  for (int i = 0; i < 4; ++i) m.q0[i] = q0[i];
  Mat6 k = Mat6::Zero();
  k.topLeftCorner<3, 3>() = -200.0 * Eigen::Matrix3d::Identity();
  k.bottomRightCorner<3, 3>() = -k_rot * Eigen::Matrix3d::Identity() - 0.5 * so3::Hat(torque0);
  k(0, 4) = k(4, 0) = 0.2;  // N/rad and N m/m
  for (int i = 0; i < 3; ++i) {
    m.torque0[i] = torque0[i];
    for (int j = 0; j < 3; ++j) m.K[i][j] = k(i, j);
  }
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) m.K6[i][j] = k(i, j);
  }
  return m;
}

Mat6 K6Of(const LocalModel& m) {
  Mat6 k;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) k(i, j) = m.K6[i][j];
  }
  return k;
}

double Norm(const double v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

TEST(DeviceWrenchModelTest, K6WithinTheLimitsPassesUnchanged) {
  const force_model_t msg = WrenchModel(Eigen::Vector3d(0.02, 0.0, -0.01));
  LocalModel m;
  std::string why;
  ASSERT_EQ(PrepareModel(msg, 0, Limits(), &m, &why), ModelVerdict::kAccepted) << why;
  ASSERT_TRUE(m.has_wrench);
  Mat6 sent;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) sent(i, j) = msg.K6[i][j];
  }
  EXPECT_LT((K6Of(m) - sent).norm(), 1e-9 * sent.norm());
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(m.q0[i], msg.q0[i], 1e-15);
}

TEST(DeviceWrenchModelTest, TorqueBlockStiffnessIsClampedAndNegativeStiffnessRemoved) {
  const Eigen::Vector3d tau(0.02, 0.0, 0.0);
  for (double k_rot : {1.0, -0.05}) {
    const force_model_t msg = WrenchModel(tau, k_rot);
    LocalModel m;
    std::string why;
    ASSERT_EQ(PrepareModel(msg, 0, Limits(), &m, &why), ModelVerdict::kStiffnessClamped) << why;
    const Mat6 k = K6Of(m);
    // The rotational stiffness -sym(dτ/dr) lies in [0, max_torque_stiffness].
    const Eigen::Matrix3d s = -0.5 * (k.bottomRightCorner<3, 3>() + k.bottomRightCorner<3, 3>().transpose());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(s);
    EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12) << k_rot;
    EXPECT_LE(eig.eigenvalues().maxCoeff(), Limits().max_torque_stiffness_nm_per_rad + 1e-12) << k_rot;
    // The whole 6x6 stiffness in (u, ℓ r) is positive semi-definite.
    const double ell = std::sqrt(Limits().max_torque_stiffness_nm_per_rad / Limits().max_stiffness_n_per_m);
    Eigen::Matrix<double, 6, 1> t;
    t << 1, 1, 1, 1 / ell, 1 / ell, 1 / ell;
    const Mat6 kp = t.asDiagonal() * k * t.asDiagonal();
    Eigen::SelfAdjointEigenSolver<Mat6> eig6(-0.5 * (kp + kp.transpose()));
    EXPECT_GE(eig6.eigenvalues().minCoeff(), -1e-9);
    // The antisymmetric -½[τ0]× is kept.
    const Eigen::Matrix3d skew = 0.5 * (k.bottomRightCorner<3, 3>() - k.bottomRightCorner<3, 3>().transpose());
    EXPECT_LT((skew + 0.5 * so3::Hat(tau)).norm(), 1e-12);
  }
}

TEST(DeviceWrenchModelTest, NonFiniteWrenchModelsNeverReachTheServo) {
  for (int field = 0; field < 3; ++field) {
    force_model_t msg = WrenchModel(Eigen::Vector3d(0.01, 0.0, 0.0));
    if (field == 0) msg.K6[4][2] = kNaN;
    if (field == 1) msg.torque0[1] = kNaN;
    if (field == 2) msg.q0[0] = kNaN;
    LocalModel m;
    m.seq = -5;
    std::string why;
    EXPECT_EQ(PrepareModel(msg, 0, Limits(), &m, &why), ModelVerdict::kRejected) << field;
    EXPECT_EQ(m.seq, -5);
  }
  // A zero quaternion is no orientation.
  force_model_t msg = WrenchModel(Eigen::Vector3d(0.01, 0.0, 0.0));
  msg.q0[0] = msg.q0[1] = msg.q0[2] = msg.q0[3] = 0.0;
  LocalModel m;
  EXPECT_EQ(PrepareModel(msg, 0, Limits(), &m, nullptr), ModelVerdict::kRejected);
}

// Runs `ticks` ticks at the pose with the model fresh; returns the last output.
SafetyOutput RunTicks(ForceSafety* s, LocalModel* m, const double pos[3], const double q[4], int ticks,
                 int64_t* now, std::vector<double>* torque_x = nullptr) {
  SafetyOutput out;
  for (int i = 0; i < ticks; ++i) {
    m->receive_us = *now;
    s->Step(pos, q, true, m, *now, &out);
    if (torque_x != nullptr) torque_x->push_back(out.torque_nm[0]);
    *now += kTickUs;
  }
  return out;
}

TEST(DeviceWrenchSafetyTest, TorqueIsBoundedAndSlewLimited) {
  const SafetyLimits limits = Limits();
  ForceSafety s(limits, true, true);
  int64_t now = 0;
  const double pos[3] = {0.0, 0.0, 0.0};
  // Far above the bound: clamped to max_torque_nm along τ0.
  force_model_t msg = WrenchModel(Eigen::Vector3d(0.2, 0.0, 0.0));
  LocalModel m;
  ASSERT_NE(PrepareModel(msg, 0, limits, &m, nullptr), ModelVerdict::kRejected);
  SafetyOutput out = RunTicks(&s, &m, pos, m.q0, 200, &now);
  EXPECT_NEAR(out.torque_nm[0], limits.max_torque_nm, 1e-12);
  EXPECT_NEAR(std::hypot(out.torque_nm[1], out.torque_nm[2]), 0.0, 1e-12);
  EXPECT_TRUE(out.torque_clamped);
  EXPECT_GT(s.counters().torque_clamps.load(), 0u);
  // A reversal is a ramp at the slew limit (0.02 N m per tick), never a step.
  msg = WrenchModel(Eigen::Vector3d(-0.2, 0.0, 0.0));
  ASSERT_NE(PrepareModel(msg, now, limits, &m, nullptr), ModelVerdict::kRejected);
  std::vector<double> tx;
  const uint64_t slews = s.counters().torque_slew_limits.load();
  out = RunTicks(&s, &m, pos, m.q0, 10, &now, &tx);
  const double step = limits.max_torque_rate_nm_per_s * limits.tick_period_s;
  double previous = limits.max_torque_nm;
  for (double t : tx) {
    EXPECT_LE(std::abs(t - previous), step + 1e-15);
    previous = t;
  }
  EXPECT_NEAR(tx[0], limits.max_torque_nm - step, 1e-12);
  EXPECT_NEAR(tx.back(), -limits.max_torque_nm, 1e-12);
  EXPECT_EQ(s.counters().torque_slew_limits.load() - slews, 5u);  // 0.1 N m at 0.02 per tick
}

TEST(DeviceWrenchSafetyTest, BadModelsAndPosesTakeTheTorqueToZero) {
  const SafetyLimits limits = Limits();
  ForceSafety s(limits, true, true);
  int64_t now = 0;
  const double pos[3] = {0.0, 0.0, 0.0};
  LocalModel m;
  ASSERT_NE(PrepareModel(WrenchModel(Eigen::Vector3d(0.03, 0.0, 0.0)), 0, limits, &m, nullptr),
            ModelVerdict::kRejected);
  SafetyOutput out = RunTicks(&s, &m, pos, m.q0, 200, &now);
  ASSERT_NEAR(out.torque_nm[0], 0.03, 1e-12);
  // A model that is NaN inside (past PrepareModel's checks): zero, through the slew limit.
  LocalModel bad = m;
  bad.torque0_nm[0] = kNaN;
  out = RunTicks(&s, &bad, pos, m.q0, 1, &now);
  EXPECT_NEAR(out.torque_nm[0], 0.03 - 0.02, 1e-12);
  out = RunTicks(&s, &bad, pos, m.q0, 5, &now);
  EXPECT_EQ(Norm(out.torque_nm), 0.0);
  EXPECT_EQ(s.counters().nonfinite_outputs.load(), 0u);
  // STATUS_INVALID: a zero model, zero torque.
  out = RunTicks(&s, &m, pos, m.q0, 100, &now);
  force_model_t invalid = WrenchModel(Eigen::Vector3d(0.03, 0.0, 0.0));
  invalid.status = force_model_t::STATUS_INVALID;
  LocalModel zero;
  ASSERT_EQ(PrepareModel(invalid, now, limits, &zero, nullptr), ModelVerdict::kInvalidStatus);
  out = RunTicks(&s, &zero, pos, m.q0, 10, &now);
  EXPECT_EQ(Norm(out.torque_nm), 0.0);
  // A NaN orientation is a bad pose: force and torque fade at their slew limits.
  out = RunTicks(&s, &m, pos, m.q0, 100, &now);
  const double nan_q[4] = {kNaN, 0.0, 0.0, 0.0};
  s.Step(pos, nan_q, true, &m, now, &out);
  EXPECT_TRUE(out.pose_rejected);
  EXPECT_NEAR(out.torque_nm[0], 0.03 - 0.02, 1e-12);
  for (double v : out.force_n) EXPECT_TRUE(std::isfinite(v));
}

// The 6-DoF model at a turned pose: F and τ from K6 with r = log(R R0ᵀ); a device that
// senses orientation without torque output renders the force (with the coupling) and
// no torque; one that senses nothing renders f0 + K (u - u0).
TEST(DeviceWrenchSafetyTest, SixDofModelRendersTheRotationCoupling) {
  const SafetyLimits limits = Limits();
  LocalModel m;
  ASSERT_NE(PrepareModel(WrenchModel(Eigen::Vector3d(0.02, 0.0, 0.0)), 0, limits, &m, nullptr),
            ModelVerdict::kRejected);
  const double pos[3] = {0.001, 0.0, 0.0};
  const Eigen::Vector3d r(0.0, 0.3, 0.0);  // turned about y: the coupling K6[0][4] acts
  const Eigen::Vector4d q0(m.q0[0], m.q0[1], m.q0[2], m.q0[3]);
  const Eigen::Quaterniond turned = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY())) *
                                    Eigen::Quaterniond(q0[0], q0[1], q0[2], q0[3]);
  const double q[4] = {turned.w(), turned.x(), turned.y(), turned.z()};
  double f[3], t[3];
  EvaluateLocalModel(m, pos, q, f, t);
  EXPECT_NEAR(f[0], 0.5 - 200.0 * 0.001 + 0.2 * 0.3, 1e-12);
  // τ = τ0 + K6[τ_y][u_x] Δx - k_rot r - ½ τ0 × r, τ0 × r = (0, 0, 0.02 * 0.3).
  EXPECT_NEAR(t[0], 0.02, 1e-12);
  EXPECT_NEAR(t[1], 0.2 * 0.001 - 0.01 * 0.3, 1e-12);
  EXPECT_NEAR(t[2], -0.5 * 0.02 * 0.3, 1e-12);

  int64_t now = 0;
  ForceSafety sensing(limits, true, false);
  SafetyOutput out = RunTicks(&sensing, &m, pos, q, 200, &now);
  EXPECT_NEAR(out.force_n[0], f[0], 1e-12);
  EXPECT_EQ(Norm(out.torque_nm), 0.0);
  now = 0;
  ForceSafety blind(limits, false, false);
  out = RunTicks(&blind, &m, pos, q, 200, &now);
  EXPECT_NEAR(out.force_n[0], 0.5 - 200.0 * 0.001, 1e-12);
  EXPECT_EQ(Norm(out.torque_nm), 0.0);
}

TEST(DeviceWrenchSafetyTest, DevicesWithoutTorqueOutputGetNoTorqueBound) {
  DeviceCapabilities caps;
  caps.max_force_n = 5.0;
  caps.max_stiffness_n_per_m = 1000.0;
  caps.workspace_radius_m = 0.1;
  EXPECT_EQ(LimitsFrom(caps, nullptr).max_torque_nm, 0.0);
  caps.has_torque_output = true;
  caps.max_torque_nm = 0.03;
  EXPECT_EQ(LimitsFrom(caps, nullptr).max_torque_nm, 0.03);
  caps.max_torque_nm = 1.0;
  EXPECT_EQ(LimitsFrom(caps, nullptr).max_torque_nm, SafetyLimits{}.max_torque_nm);
}

// sim-path follows a rolling path (a rod scene's roll_deg): the orientation turns at the
// angular speed while the position stays, and it keeps the commanded torque.
int64_t g_now_us = 0;
int64_t Clock() { return g_now_us; }

TEST(DeviceWrenchSafetyTest, SimPathRollsAndKeepsTheCommandedTorque) {
  const double turn = 2.0 * std::numbers::pi;
  ScriptedPath path({{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}, {{0.0, 0.0, 0.0}, {2.0 * turn, 0.0, 0.0}}, 0.02,
                    std::numbers::pi);  // half a turn per second: 4 s out
  g_now_us = 0;
  SimPathDevice device(path, &Clock);
  ASSERT_TRUE(device.Open(nullptr));
  EXPECT_TRUE(device.capabilities().has_orientation);
  EXPECT_TRUE(device.capabilities().has_torque_output);
  DeviceState st;
  ASSERT_TRUE(device.Read(&st));
  for (double t_s : {0.5, 1.0, 2.5, 5.0}) {
    g_now_us = static_cast<int64_t>(t_s * 1e6);
    ASSERT_TRUE(device.Read(&st));
    const double roll = std::numbers::pi * (t_s <= 4.0 ? t_s : 8.0 - t_s);
    const Eigen::Quaterniond expected(Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()));
    const double dot = st.orientation[0] * expected.w() + st.orientation[1] * expected.x() +
                       st.orientation[2] * expected.y() + st.orientation[3] * expected.z();
    EXPECT_NEAR(std::abs(dot), 1.0, 1e-12) << t_s;
    EXPECT_EQ(Norm(st.position_m), 0.0);
  }
  const double force[3] = {0.1, 0.0, 0.0}, torque[3] = {0.0, -0.02, 0.01};
  ASSERT_TRUE(device.Command(force, torque));
  EXPECT_EQ(device.last_torque_nm()[1], -0.02);
  EXPECT_EQ(device.last_torque_nm()[2], 0.01);
}

// The one envelope the force and the torque both go through (LimitVector): the norm
// clamp, then the slew limit from the last output, a non-finite input aimed at zero
// through the slew limit, and last updated to the output.
TEST(DeviceEnvelopeTest, LimitVectorClampsSlewsAndNeverPassesNonFinite) {
  double last[3] = {0.0, 0.0, 0.0};
  double v[3] = {6.0, 8.0, 0.0};  // |v| = 10 > 3: clamped to (1.8, 2.4, 0), then slewed by 1
  Limited l = LimitVector(v, 3.0, 1.0, last);
  EXPECT_TRUE(l.clamped);
  EXPECT_TRUE(l.slew_limited);
  EXPECT_FALSE(l.nonfinite);
  EXPECT_NEAR(v[0], 0.6, 1e-15);
  EXPECT_NEAR(v[1], 0.8, 1e-15);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(last[k], v[k]);
  // Within both limits: passed as it is.
  double w[3] = {1.0, 1.2, 0.1};
  l = LimitVector(w, 3.0, 1.0, last);
  EXPECT_FALSE(l.clamped || l.slew_limited || l.nonfinite);
  EXPECT_EQ(w[0], 1.0);
  EXPECT_EQ(w[2], 0.1);
  // NaN and inf: no direction to keep; the output walks to zero at the slew limit.
  double bad[3] = {kNaN, 1.0, std::numeric_limits<double>::infinity()};
  l = LimitVector(bad, 3.0, 0.5, last);
  EXPECT_TRUE(l.clamped);
  EXPECT_TRUE(l.slew_limited);
  EXPECT_FALSE(l.nonfinite);
  const double before = std::sqrt(1.0 + 1.44 + 0.01);
  EXPECT_NEAR(Norm(bad), before - 0.5, 1e-12);
  for (double x : bad) EXPECT_TRUE(std::isfinite(x));
  // Overflowing arithmetic cannot leak: a huge finite last and a huge step.
  double huge_last[3] = {1e308, 1e308, 0.0};
  double huge[3] = {-1e308, -1e308, 0.0};
  l = LimitVector(huge, 1e308, 1e308, huge_last);
  for (double x : huge) EXPECT_TRUE(std::isfinite(x));
}

}  // namespace
}  // namespace snapthread::device
