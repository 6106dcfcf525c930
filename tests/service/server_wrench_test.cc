// The rod's wrench and 6x6 stiffness (issue 14 item 3; server/server_wrench.h): the SO(3)
// pieces of the chart change against finite differences, then the server's own path
// (ApplyGraspPoses -> tracker -> BuildForceModel) on scenes/rod_greenhill.yaml: K6
// against central differences of the wrench over device pose perturbations, each one a
// re-solved equilibrium, and the torque before the buckle against GJ Φ / L.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "messages/pose_mapping.h"
#include "safety.h"
#include "numeric/so3.h"
#include "server_messages.h"
#include "server_wrench.h"
#include "grasp_poses.h"
#include "test_support.h"
#include "tracking/make_tracker.h"

namespace snapthread::server {
namespace {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

// The rotation vector of exp([s]×) exp([φ0]×) that continues φ0.
V3 Compose(const V3& s, const V3& phi0) {
  const M3 r = so3::Exp(s) * so3::Exp(phi0);
  const Eigen::Quaterniond q(r);
  return so3::NearestRepresentative(so3::LogQuaternion(q.w(), q.x(), q.y(), q.z()), phi0);
}

const V3 kPhis[] = {V3(0.0, 0.0, 0.0), V3(1e-3, -2e-3, 5e-4), V3(0.3, -0.2, 0.1),
                    V3(2.9, 0.3, -0.2), V3(-1.0, 2.5, 1.2), V3(3.6, -0.4, 0.5)};

TEST(So3Test, LeftJacobianTakesWorldPerturbationsToTheRotationVector) {
  const double h = 1e-6;
  for (const V3& phi : kPhis) {
    const M3 jl = so3::LeftJacobian(phi);
    for (int k = 0; k < 3; ++k) {
      // exp(φ + h e_k) exp(-φ) = exp(h J_l e_k) + O(h²).
      const M3 d = so3::Exp(phi + h * V3::Unit(k)) * so3::Exp(phi).transpose();
      const Eigen::Quaterniond q(d);
      const V3 r = so3::LogQuaternion(q.w(), q.x(), q.y(), q.z()) / h;
      EXPECT_LT((r - jl.col(k)).norm(), 1e-5) << "phi " << phi.transpose() << " k " << k;
    }
  }
}

TEST(So3Test, LeftJacobianDerivativeMatchesFiniteDifferences) {
  const double h = 1e-5;
  const V3 w(0.4, -0.7, 0.2);
  for (const V3& phi : kPhis) {
    const M3 fd = (so3::LeftJacobian(phi + h * w) - so3::LeftJacobian(phi - h * w)) / (2.0 * h);
    EXPECT_LT((fd - so3::LeftJacobianDerivative(phi, w)).norm(), 1e-8) << phi.transpose();
  }
}

// Σ_k g_k ∂²φ_k/∂s_i∂s_j of the chart change φ(s) = log(exp([s]×) exp([φ0]×)) against
// central second differences of g·φ(s); its antisymmetric part is zero (a second
// derivative is symmetric: the ½ (e_i × e_j) term cancels that of the D term), which is
// the check on the derivation in server_wrench.h.
TEST(So3Test, ChartCurvatureIsTheSecondDerivativeOfTheChartChange) {
  const V3 g(0.7, -1.3, 0.4);
  const double h = 1e-4;
  for (const V3& phi0 : kPhis) {
    const M3 jinv = so3::LeftJacobian(phi0).inverse();
    const M3 t = ChartCurvature(phi0, jinv.transpose() * g);
    EXPECT_LT((t - t.transpose()).norm(), 1e-12 * (1.0 + t.norm())) << phi0.transpose();
    auto f = [&](const V3& s) { return g.dot(Compose(s, phi0)); };
    M3 fd;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        const V3 a = h * V3::Unit(i), b = h * V3::Unit(j);
        fd(i, j) = (f(a + b) - f(a - b) - f(b - a) + f(-a - b)) / (4.0 * h * h);
      }
    }
    EXPECT_LT((fd - t).norm(), 1e-6 * (1.0 + t.norm())) << phi0.transpose() << "\n" << fd << "\n" << t;
  }
}

TEST(So3Test, QuaternionsAndRepresentatives) {
  for (const V3& phi : kPhis) {
    const Eigen::Vector4d q = so3::ExpQuaternion(phi);
    const V3 back = so3::LogQuaternion(q[0], q[1], q[2], q[3]);
    EXPECT_LT((so3::Exp(back) - so3::Exp(phi)).norm(), 1e-12);
    EXPECT_LE(back.norm(), std::numbers::pi + 1e-12);
    EXPECT_LT((so3::NearestRepresentative(back, phi) - phi).norm(), 1e-12) << phi.transpose();
    // R R0ᵀ for R = exp(r) R0.
    const V3 r(0.1, -0.05, 0.2);
    const Eigen::Vector4d q1 = so3::ExpQuaternion(Compose(r, phi));
    EXPECT_LT((so3::RotationVectorBetween(q1.data(), q.data()) - r).norm(), 1e-12);
  }
  // Whole turns of a roll: from 0 to 2π and 4π along the previous value.
  const V3 x = V3::UnitX();
  EXPECT_LT((so3::NearestRepresentative(V3::Zero(), 6.2 * x) - 2.0 * std::numbers::pi * x).norm(), 1e-15);
  EXPECT_LT((so3::NearestRepresentative(-0.5 * x, 11.0 * x) - (4.0 * std::numbers::pi - 0.5) * x).norm(), 1e-12);
}

// ---------------------------------------------------------------- the server's wrench

// The server's solve path for one grasp, in process.
class RodWrench {
 public:
  explicit RodWrench(std::vector<SceneOverride> overrides = {})
      : scene_(LoadScene(test_support::ScenePath("rod_greenhill.yaml"), With(std::move(overrides)))),
        tracker_(MakeTracker(scene_)),
        rest_(messages::RestGripDirection(scene_)) {
    tracker_->Reset(scene_.grasp_start);
    position_ = messages::ControlsToPosition(scene_.device, scene_.grasp_layout, scene_.grasp_start);
  }

  // One pose: device metres and the device rotation vector.
  force_model_t Solve(const V3& position_m, const V3& rotation) {
    ReceivedPose pose{};
    pose.state = device_state_t{};
    for (int k = 0; k < 3; ++k) pose.state.position[k] = position_m[k];
    const Eigen::Vector4d q = so3::ExpQuaternion(rotation);
    for (int k = 0; k < 4; ++k) pose.state.orientation[k] = q[k];
    Vec u = tracker_->control();
    Vec renamed;
    ApplyGraspPoses(scene_, rest_, {pose}, &u, &renamed);
    if (renamed != tracker_->control()) tracker_->RelabelControls(renamed);
    const TrackResult& r = tracker_->Update(u);
    EXPECT_EQ(r.summary.termination, Termination::kConverged) << "at " << rotation.transpose();
    ForceModelInputs in;
    in.mapping = &scene_.device;
    in.model = &tracker_->model();
    in.u = u;
    in.position_m = position_m;
    in.result = &r;
    in.layout = &scene_.grasp_layout;
    return BuildForceModel(in);
  }

  // Walks the hand in steps of at most 2 degrees and 0.2 mm to the pose.
  force_model_t WalkTo(const V3& position_m, const V3& rotation) {
    const int steps = std::max(1, static_cast<int>(std::ceil(std::max(
                                      (rotation - rotation_).norm() / (2.0 * std::numbers::pi / 180.0),
                                      (position_m - position_).norm() / 2e-4))));
    force_model_t m;
    for (int i = 1; i <= steps; ++i) {
      const double a = static_cast<double>(i) / steps;
      m = Solve(position_ + a * (position_m - position_), rotation_ + a * (rotation - rotation_));
    }
    position_ = position_m;
    rotation_ = rotation;
    return m;
  }

  const Scene& scene() const { return scene_; }
  const EquilibriumTracker& tracker() const { return *tracker_; }

 private:
  static std::vector<SceneOverride> With(std::vector<SceneOverride> o) {
    // Equilibria tight enough for central differences of their forces.
    o.push_back({"solver.cutoff", "1e-11"});
    return o;
  }
  Scene scene_;
  std::unique_ptr<EquilibriumTracker> tracker_;
  V3 rest_;
  V3 position_;
  V3 rotation_ = V3::Zero();
};

using Vec6 = Eigen::Matrix<double, 6, 1>;

Vec6 Wrench(const force_model_t& m) {
  Vec6 w;
  for (int i = 0; i < 3; ++i) {
    w[i] = m.f0[i];
    w[3 + i] = m.torque0[i];
  }
  return w;
}

// K6 against central differences of the wrench, each perturbed pose re-solved from the
// base equilibrium (and the base solved again after it). Position steps h_p metres,
// rotations exp([h e_k]×) R0 of h_r radians. Per column, relative to its largest entry.
void ExpectK6MatchesFiniteDifferences(RodWrench* rod, const V3& position, const V3& rotation,
                                      double tolerance) {
  const force_model_t base = rod->WalkTo(position, rotation);
  ASSERT_EQ(base.has_wrench, 1);
  ASSERT_EQ(base.status, force_model_t::STATUS_REGULAR);
  // Central differences at h and h/2, Richardson-extrapolated (error O(h⁴)): the buckled
  // rod's wrench curves enough that a plain central difference at h = 1e-5 m is off by
  // ~3e-4 of K6.
  auto central = [&](int j, double h) {
    Vec6 plus = Vec6::Zero(), minus = Vec6::Zero();
    for (int sign : {1, -1}) {
      V3 p = position, r = rotation;
      if (j < 3) {
        p[j] += sign * h;
      } else {
        r = Compose(sign * h * V3::Unit(j - 3), rotation);
      }
      (sign > 0 ? plus : minus) = Wrench(rod->Solve(p, r));
      rod->Solve(position, rotation);
    }
    return Vec6((plus - minus) / (2.0 * h));
  };
  const double hp = 2e-5, hr = 2e-4;
  double worst = 0.0;
  for (int j = 0; j < 6; ++j) {
    const double h = j < 3 ? hp : hr;
    const Vec6 fd = (4.0 * central(j, 0.5 * h) - central(j, h)) / 3.0;
    Vec6 k;
    for (int i = 0; i < 6; ++i) k[i] = base.K6[i][j];
    const double scale = std::max(k.lpNorm<Eigen::Infinity>(), fd.lpNorm<Eigen::Infinity>());
    worst = std::max(worst, (fd - k).lpNorm<Eigen::Infinity>() / scale);
    EXPECT_LT((fd - k).lpNorm<Eigen::Infinity>(), tolerance * scale)
        << "column " << j << " at rotation " << rotation.transpose() << "\nK6  " << k.transpose()
        << "\nFD  " << fd.transpose();
  }
  std::printf("K6 vs differences at rotation (%.3f, %.3f, %.3f): worst column error %.2e of its scale\n",
              rotation[0], rotation[1], rotation[2], worst);
  // K stays K6's top-left block (3-DoF devices are unchanged).
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) EXPECT_EQ(base.K[i][j], base.K6[i][j]);
  }
}

TEST(RodWrenchTest, K6MatchesCentralDifferencesOfTheWrench) {
  RodWrench rod;
  // Twisted by a quarter turn, the hand a little off the rest pose.
  ExpectK6MatchesFiniteDifferences(&rod, V3(4e-4, 6e-4, -5e-4), V3(std::numbers::pi / 2, 0.0, 0.0), 1e-4);
  // |φ0| near π about a tilted axis: the chart change is far from the identity.
  const V3 near_pi(2.9, 0.3, -0.2);
  ExpectK6MatchesFiniteDifferences(&rod, V3(-3e-4, 2e-4, 4e-4), near_pi, 1e-4);
  const Eigen::Vector4d q0 = so3::ExpQuaternion(near_pi);
  EXPECT_GT(so3::LogQuaternion(q0[0], q0[1], q0[2], q0[3]).norm(), 2.9);
}

TEST(RodWrenchTest, K6MatchesCentralDifferencesOnTheBuckledRod) {
  RodWrench rod;
  // 620 degrees, past Greenhill's 515: the rod bows out. The server has renamed the
  // roll's rotation vector on the way (|φ| <= 1.25π at every update).
  const V3 rotation(620.0 * std::numbers::pi / 180.0, 0.05, -0.03);
  ExpectK6MatchesFiniteDifferences(&rod, V3(0.0, 1e-7, 0.0), rotation, 1e-4);
  EXPECT_GT(rod.tracker().last().probe, 0.02) << "the rod should have buckled";
  EXPECT_LE(rod.tracker().control().tail<3>().norm(), kRelabelAngle);
}

// The straight rod before the buckle carries the torque -GJ Φ / L about its axis (the
// discrete rod: GJ Φ / ((n - 1) ℓ), its twist acts between the held edges' midpoints;
// tests/rod_scene_test.cc), in N m through the device mapping: N/s per model energy unit.
TEST(RodWrenchTest, TorqueBeforeTheBuckleIsGJPhiOverL) {
  RodWrench rod;
  const Scene& sc = rod.scene();
  const double gj = sc.params.Number("twist_stiffness");
  const double length = sc.params.Number("length");
  const int n = sc.params.Integer("n");
  const double units = sc.device.newtons_per_model_force / sc.device.model_units_per_metre;
  const V3 start = messages::ControlsToPosition(sc.device, sc.grasp_layout, sc.grasp_start);
  // The grasp sits e = 1e-6 off the axis (the scene's imperfection): a clamped-clamped
  // rod whose end is offset by e carries the bending moment 6 EI e / L², transverse.
  const double offset = sc.grasp_start[1];
  const double bending = units * 6.0 * sc.params.Number("bend_stiffness") * offset / (length * length);
  for (double degrees : {90.0, 200.0, 400.0}) {
    const double phi = degrees * std::numbers::pi / 180.0;
    const force_model_t m = rod.WalkTo(start, V3(phi, 0.0, 0.0));
    ASSERT_EQ(m.has_wrench, 1);
    const double expected = -units * gj * phi / length * n / (n - 1.0);
    EXPECT_NEAR(m.torque0[0], expected, 1e-6 * std::abs(expected)) << degrees << " degrees";
    EXPECT_LT(std::hypot(m.torque0[1], m.torque0[2]), 1.5 * bending + 1e-6 * std::abs(expected));
    EXPECT_LT(rod.tracker().last().probe, 1e-4);
  }
}

// The device's 6-DoF local model (device_client/safety.h, EvaluateLocalModel) built from
// the server's message reproduces the server's wrench, re-solved at a nearby pose, to
// second order: the error shrinks fourfold when the offset halves.
TEST(RodWrenchTest, DeviceLocalModelReproducesTheWrenchToSecondOrder) {
  RodWrench rod;
  const V3 position(3e-4, -2e-4, 1e-4);
  const V3 rotation(2.0, 0.2, -0.1);
  const force_model_t base = rod.WalkTo(position, rotation);
  ASSERT_EQ(base.has_wrench, 1);
  // The model as sent (the clamp is safety.h's business, tested apart).
  device::LocalModel local;
  local.status = base.status;
  local.has_torque = true;
  local.has_wrench = true;
  for (int i = 0; i < 3; ++i) {
    local.u0_m[i] = base.u0[i];
    local.f0_n[i] = base.f0[i];
    local.torque0_nm[i] = base.torque0[i];
    for (int j = 0; j < 3; ++j) local.K_n_per_m[i][j] = base.K[i][j];
  }
  for (int i = 0; i < 4; ++i) local.q0[i] = base.q0[i];
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) local.K6[i][j] = base.K6[i][j];
  }
  const V3 dp(4e-4, -2e-4, 3e-4);   // metres
  const V3 dr(0.03, -0.04, 0.025);  // radians
  double error[2][2];               // [scale][force, torque]
  for (int k = 0; k < 2; ++k) {
    const double eps = k == 0 ? 1.0 : 0.5;
    const V3 p = position + eps * dp;
    const V3 r = Compose(eps * dr, rotation);
    const Vec6 server = Wrench(rod.Solve(p, r));
    rod.Solve(position, rotation);
    const Eigen::Vector4d q = so3::ExpQuaternion(r);
    double f[3], t[3];
    device::EvaluateLocalModel(local, p.data(), q.data(), f, t);
    error[k][0] = (server.head<3>() - V3(f[0], f[1], f[2])).norm();
    error[k][1] = (server.tail<3>() - V3(t[0], t[1], t[2])).norm();
  }
  for (int c = 0; c < 2; ++c) {
    const char* what = c == 0 ? "force" : "torque";
    const double ratio = error[0][c] / error[1][c];
    std::printf("local model %s error: %.3e at the offset, %.3e at half of it (ratio %.2f)\n", what, error[0][c],
                error[1][c], ratio);
    EXPECT_GT(ratio, 3.5) << what << ": errors " << error[0][c] << " " << error[1][c];
    EXPECT_LT(ratio, 4.5) << what << ": errors " << error[0][c] << " " << error[1][c];
  }
}

}  // namespace
}  // namespace snapthread::server
