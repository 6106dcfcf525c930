// Unit tests of the server's message building (units, planar constraint, torque, status
// flags, never NaN) and pose mapping, without any transport.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "messages/pose_mapping.h"
#include "server_messages.h"
#include "models/models.h"
#include "messages/validate.h"

namespace snapthread::server {
namespace {

DeviceMapping TestMapping() {
  DeviceMapping m;
  m.model_units_per_metre = 50.0;
  m.newtons_per_model_force = 2.0;
  m.max_stiffness_n_per_m = 800.0;
  m.model_origin = {9.0, 1.0, 0.25};
  return m;
}

TrackResult FakeResult(int nu, double scale) {
  TrackResult r;
  r.summary.termination = Termination::kConverged;
  r.force = Vec::LinSpaced(nu, 1.0 * scale, nu * scale);
  r.stiffness = Mat::Zero(nu, nu);
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nu; ++j) r.stiffness(i, j) = -(1.0 + i + j) * scale;
  }
  return r;
}

TEST(PoseMappingTest, PlanarAndSpatialControls) {
  const DeviceMapping map = TestMapping();
  // The layouts a scene carries (Scene::grasp_layout): no model is built.
  const GraspLayout curve{2, false};
  const Eigen::Vector3d pos(0.01, -0.02, 0.3);
  const Eigen::Vector4d q(1, 0, 0, 0);
  const Vec u = messages::PoseToControls(map, curve, pos, q);
  ASSERT_EQ(u.size(), 2);
  EXPECT_DOUBLE_EQ(u[0], 9.0 + 50.0 * 0.01);
  EXPECT_DOUBLE_EQ(u[1], 1.0 - 50.0 * 0.02);
  // Inverse: x, y back, z on the model plane.
  const Eigen::Vector3d back = messages::ControlsToPosition(map, curve, u);
  EXPECT_NEAR(back[0], 0.01, 1e-15);
  EXPECT_NEAR(back[1], -0.02, 1e-15);
  EXPECT_DOUBLE_EQ(back[2], messages::PlanarZ0(map));
  EXPECT_DOUBLE_EQ(messages::PlanarZ0(map), -0.25 / 50.0);

  const GraspLayout thread{3, true};
  ASSERT_EQ(thread.NumControls(), 6);
  // 90 degrees about z: (1,0,0) -> (0,1,0).
  const double h = std::sqrt(0.5);
  const Vec u3 = messages::PoseToControls(map, thread, pos, Eigen::Vector4d(h, 0, 0, h));
  EXPECT_DOUBLE_EQ(u3[2], 0.25 + 50.0 * 0.3);
  EXPECT_NEAR(u3[3], 0.0, 1e-15);
  EXPECT_NEAR(u3[4], 1.0, 1e-15);
  EXPECT_NEAR(u3[5], 0.0, 1e-15);
  // A non-unit quaternion is normalised; 180 degrees about z gives -x.
  const Eigen::Vector3d d = messages::GripDirection(Eigen::Vector4d(0, 0, 0, 1.7));
  EXPECT_NEAR(d[0], -1.0, 1e-15);
  EXPECT_NEAR(d.norm(), 1.0, 1e-15);

  // A scene that starts with the grip along -x: the device at rest holds it so, and
  // turning the device 90 degrees about z turns the grip with it, to -y.
  const Eigen::Vector3d rest(-2.0, 0.0, 0.0);
  const Vec at_rest = messages::PoseToControls(map, thread, pos, Eigen::Vector4d(1, 0, 0, 0), rest);
  EXPECT_NEAR(at_rest[3], -1.0, 1e-15);
  EXPECT_NEAR(at_rest[4], 0.0, 1e-15);
  const Vec turned = messages::PoseToControls(map, thread, pos, Eigen::Vector4d(h, 0, 0, h), rest);
  EXPECT_NEAR(turned[3], 0.0, 1e-15);
  EXPECT_NEAR(turned[4], -1.0, 1e-15);
  EXPECT_NEAR(turned[5], 0.0, 1e-15);
  // About x the -x grip does not move.
  const Vec rolled = messages::PoseToControls(map, thread, pos, Eigen::Vector4d(h, h, 0, 0), rest);
  EXPECT_NEAR(rolled[3], -1.0, 1e-15);

  Scene scene;
  scene.grasp_layout = thread;
  scene.grasp_start = (Vec(6) << 1, 2, 3, 0, 0, 5).finished();
  const Eigen::Vector3d r = messages::RestGripDirection(scene);
  EXPECT_NEAR(r[2], 1.0, 1e-15);
  EXPECT_NEAR(r.norm(), 1.0, 1e-15);
  scene.grasp_layout = curve;
  scene.grasp_start = (Vec(2) << 1, 2).finished();
  EXPECT_EQ(messages::RestGripDirection(scene), Eigen::Vector3d::UnitX());
}

TEST(ServerMessagesTest, PlanarForceModelUnitsAndPlane) {
  const DeviceMapping map = TestMapping();
  ModelParams p;
  p.model = "curve2d";
  auto model = MakeModel(p);
  const TrackResult r = FakeResult(2, 0.5);
  const ForceModelInputs in{.mapping = &map, .model = model.get(), .u = Vec::Zero(2),
                            .position_m = Eigen::Vector3d(0.01, 0.02, 0.003), .result = &r,
                            .device_seq = 41, .device_utime = 123456, .server_receive_utime = 777,
                            .solve_us = 12.4, .seq = 5, .utime = 999};
  const force_model_t m = BuildForceModel(in);
  EXPECT_EQ(m.status, force_model_t::STATUS_REGULAR);
  EXPECT_EQ(m.device_seq, 41);
  EXPECT_EQ(m.device_utime, 123456);
  EXPECT_EQ(m.server_receive_utime, 777);
  EXPECT_EQ(m.solve_us, 12);
  EXPECT_EQ(m.seq, 5);
  for (int i = 0; i < 2; ++i) {
    EXPECT_DOUBLE_EQ(m.f0[i], 2.0 * r.force[i]);
    for (int j = 0; j < 2; ++j) EXPECT_DOUBLE_EQ(m.K[i][j], 2.0 * 50.0 * r.stiffness(i, j));
    EXPECT_DOUBLE_EQ(m.K[i][2], 0.0);
    EXPECT_DOUBLE_EQ(m.K[2][i], 0.0);
  }
  // Planar constraint: f_z = -k (z - z0), k = max stiffness / 2.
  const double k = 400.0;
  EXPECT_DOUBLE_EQ(m.K[2][2], -k);
  EXPECT_NEAR(m.f0[2], -k * (0.003 - messages::PlanarZ0(map)), 1e-12);
  EXPECT_EQ(m.has_torque, 0);
  for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(m.u0[i], in.position_m[i]);
  std::string why;
  EXPECT_TRUE(messages::Validate(m, &why)) << why;
}

TEST(ServerMessagesTest, GripTorque) {
  const DeviceMapping map = TestMapping();
  auto model = MakeModel(ModelParams{.model = "thread3d"}.Set("grip_direction", true));
  TrackResult r = FakeResult(6, 1.0);
  r.force.segment<3>(3) = Eigen::Vector3d(0.0, 3.0, 0.0);  // F_d
  ForceModelInputs in;
  in.mapping = &map;
  in.model = model.get();
  in.u = Vec::Zero(6);
  in.u.segment<3>(3) = Eigen::Vector3d(2.0, 0.0, 0.0);  // d (normalised inside)
  in.result = &r;
  const force_model_t m = BuildForceModel(in);
  EXPECT_EQ(m.has_torque, 1);
  // tau = d x F_d = (1,0,0) x (0,3,0) = (0,0,3), model energy -> N m: * 2 / 50.
  EXPECT_NEAR(m.torque0[0], 0.0, 1e-15);
  EXPECT_NEAR(m.torque0[1], 0.0, 1e-15);
  EXPECT_NEAR(m.torque0[2], 3.0 * 2.0 / 50.0, 1e-15);
  for (int i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(m.f0[i], 2.0 * r.force[i]);
    for (int j = 0; j < 3; ++j) EXPECT_DOUBLE_EQ(m.K[i][j], 100.0 * r.stiffness(i, j));
  }
}

TEST(ServerMessagesTest, StatusFlags) {
  TrackResult r = FakeResult(2, 1.0);
  EXPECT_EQ(ClassifyStatus(&r), force_model_t::STATUS_REGULAR);
  r.stiffness_regularized = true;
  EXPECT_EQ(ClassifyStatus(&r), force_model_t::STATUS_NEAR_FOLD);
  r.stiffness_regularized = false;
  r.summary.status = EquilibriumStatus::kNearFold;
  EXPECT_EQ(ClassifyStatus(&r), force_model_t::STATUS_NEAR_FOLD);
  r.summary.status = EquilibriumStatus::kSnapped;
  r.snapped = true;
  EXPECT_EQ(ClassifyStatus(&r), force_model_t::STATUS_SNAPPED);
  r.summary.termination = Termination::kBudgetSpent;
  EXPECT_EQ(ClassifyStatus(&r), force_model_t::STATUS_SNAPPED);
  r.summary.termination = Termination::kLinearSolverFailed;
  EXPECT_EQ(ClassifyStatus(&r), force_model_t::STATUS_INVALID);
  r.summary.termination = Termination::kInvalidInput;
  EXPECT_EQ(ClassifyStatus(&r), force_model_t::STATUS_INVALID);
  EXPECT_EQ(ClassifyStatus(nullptr), force_model_t::STATUS_INVALID);
  // A snap spread over updates by the time budget (docs/time-budget.md).
  r.summary.termination = Termination::kSnapping;
  r.summary.status = EquilibriumStatus::kSnapping;
  r.snapped = false;
  EXPECT_EQ(ClassifyStatus(&r), force_model_t::STATUS_SNAPPING);
  // A NaN residual is a failed row, never a force model.
  r.summary.termination = Termination::kConverged;
  r.summary.status = EquilibriumStatus::kFailed;
  r.summary.residual = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(ClassifyStatus(&r), force_model_t::STATUS_INVALID);
}

TEST(ServerMessagesTest, NonFiniteResultBecomesInvalidZeroModel) {
  const DeviceMapping map = TestMapping();
  ModelParams p;
  p.model = "curve2d";
  auto model = MakeModel(p);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (int variant = 0; variant < 4; ++variant) {
    TrackResult r = FakeResult(2, 1.0);
    if (variant == 0) r.force[1] = nan;
    if (variant == 1) r.stiffness(0, 1) = inf;
    if (variant == 2) r.summary.termination = Termination::kNonFinite;
    if (variant == 3) r.summary.residual = nan;
    ForceModelInputs in;
    in.mapping = &map;
    in.model = model.get();
    in.u = Vec::Zero(2);
    in.position_m = Eigen::Vector3d(0.01, 0.0, 0.0);
    in.result = &r;
    const force_model_t m = BuildForceModel(in);
    EXPECT_TRUE(messages::Validate(m, nullptr)) << "variant " << variant;
    std::string why;
    EXPECT_TRUE(messages::Validate(m, &why)) << why;
    // A NaN residual says the state itself is not finite (issue 13: NaN or inf rows are
    // failed, never a force model), even where the force happened to be finite.
    EXPECT_EQ(m.status, force_model_t::STATUS_INVALID) << "variant " << variant;
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(m.f0[i], 0.0);
      for (int j = 0; j < 3; ++j) EXPECT_EQ(m.K[i][j], 0.0);
    }
    EXPECT_TRUE(std::isfinite(m.residual)) << "variant " << variant;
  }
  // A failed update (no result) is INVALID too, with the pose echoed.
  ForceModelInputs in;
  in.mapping = &map;
  in.model = model.get();
  in.u = Vec::Zero(2);
  in.position_m = Eigen::Vector3d(0.01, 0.02, 0.0);
  const force_model_t m = BuildForceModel(in);
  EXPECT_EQ(m.status, force_model_t::STATUS_INVALID);
  EXPECT_EQ(m.u0[1], 0.02);
}

TEST(ServerMessagesTest, ShapeCountsMatchAndValidate) {
  const DeviceMapping map = TestMapping();
  ModelParams p;
  p.model = "curve2d";
  p.Set("n", 7);
  auto model = MakeModel(p);
  const Vec u = (Vec(2) << 6.0, 0.5).finished();
  ShapeInputs in;
  in.scene = "s";
  in.mapping = &map;
  in.model = model.get();
  in.u = u;
  in.x = model->InitialState(u);
  in.force_model_units = (Vec(2) << 1.5, -2.0).finished();
  in.force_newtons = Eigen::Vector3d(3.0, -4.0, 0.0);
  in.status = force_model_t::STATUS_SNAPPED;
  in.snaps = 3;
  const thread_shape_t s = BuildShape(in);
  EXPECT_EQ(s.model, "curve2d");
  EXPECT_EQ(s.num_nodes, static_cast<int>(s.positions.size()));
  EXPECT_EQ(s.num_nodes, 8);  // n + 1 nodes
  EXPECT_DOUBLE_EQ(s.grasp[0], 6.0);
  EXPECT_DOUBLE_EQ(s.grasp[1], 0.5);
  EXPECT_DOUBLE_EQ(s.force[0], 1.5);
  EXPECT_DOUBLE_EQ(s.force_newtons[1], -4.0);
  EXPECT_EQ(s.snaps, 3);
  EXPECT_EQ(s.num_frames, 0);  // material frames are the rod's alone
  EXPECT_TRUE(s.frames.empty());
  std::string why;
  EXPECT_TRUE(messages::Validate(s, &why)) << why;
}

// Issue 14 item 3: the rod's shape carries one frame row per edge, m1 and the twist
// density. A straight rod (n = 8, L = 1) with the grasp rolled by 2 rad about it: m1 of
// edge j is turned by 2 j / 7 about +x from the clamp's +y, and every edge has the twist
// density 2 / (7 ℓ) rad per model length (the twist acts between the held edges' midpoints).
TEST(ServerMessagesTest, RodShapeCarriesMaterialFramesAndTwistDensity) {
  const DeviceMapping map = TestMapping();
  auto model = MakeModel(ModelParams{.model = "rod"}.Set("n", 8));
  const double roll = 2.0;
  const Vec u = (Vec(6) << 1.0, 0.0, 0.0, roll, 0.0, 0.0).finished();
  ShapeInputs in;
  in.scene = "rod";
  in.mapping = &map;
  in.model = model.get();
  in.u = u;
  in.x = model->InitialState(u);
  const thread_shape_t s = BuildShape(in);
  ASSERT_EQ(s.num_nodes, 9);
  ASSERT_EQ(s.num_frames, 8);
  ASSERT_EQ(s.frames.size(), 8u);
  const double ell = 1.0 / 8;
  for (int j = 0; j < 8; ++j) {
    const auto& f = s.frames[j];
    const double a = roll * j / 7;
    EXPECT_NEAR(f[0], 0.0, 1e-12) << "edge " << j;
    EXPECT_NEAR(f[1], std::cos(a), 1e-12) << "edge " << j;
    EXPECT_NEAR(f[2], std::sin(a), 1e-12) << "edge " << j;
    EXPECT_NEAR(f[3], roll / (7 * ell), 1e-9) << "edge " << j;
    // m1 is normal to its edge (nodes j, j + 1).
    double along = 0.0;
    for (int i = 0; i < 3; ++i) along += f[i] * (s.positions[j + 1][i] - s.positions[j][i]);
    EXPECT_NEAR(along, 0.0, 1e-12);
  }
  // The grip direction is the held edge's tangent (+x here), not the rotation vector
  // u[3:6] (which points along +x as well, so tilt the grasp to tell them apart).
  EXPECT_NEAR(s.grip_direction[0], 1.0, 1e-12);
  Vec tilted = u;
  tilted.segment<3>(3) << 0.0, 0.0, 0.5;  // a yaw of 0.5 rad: tangent (cos 0.5, sin 0.5, 0)
  in.u = tilted;
  in.x = model->InitialState(tilted);
  const thread_shape_t t = BuildShape(in);
  EXPECT_NEAR(t.grip_direction[0], std::cos(0.5), 1e-9);
  EXPECT_NEAR(t.grip_direction[1], std::sin(0.5), 1e-9);
  EXPECT_NEAR(t.grip_direction[2], 0.0, 1e-9);
  in.u = u;
  in.x = model->InitialState(u);
  std::string why;
  EXPECT_TRUE(messages::Validate(s, &why)) << why;
  // A state that does not fit the model gets no frames (and no nodes).
  in.x = Vec::Zero(3);
  EXPECT_EQ(BuildShape(in).num_frames, 0);
}

}  // namespace
}  // namespace snapthread::server
