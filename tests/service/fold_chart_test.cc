// Snap-ahead for a fold reached by turning the grasp (issue 17 item 5): the server sends
// the fold boundary in the device's pose chart (server/fold_chart.h) and the device
// evaluates it from its position and quaternion every tick (device_client/snap_ahead.h).
// The chart's boundary must be the fold function's own to first order: for small pose
// offsets from the fold, the side the device computes (FoldSide, the chart's a) is
// proportional to n . (u(pose) - u_fold), the fold function in the model's controls
// through the one pose mapping (messages::PoseToControls), with one factor for every
// offset. Checked for a grip direction (thread3d: the model sees the direction only, and
// the search's line leaves the unit sphere) with the hand rolled about its grip, and for
// the rod's full orientation (rotation-vector controls); a positional fold ignores the
// hand's turning; a hand a quarter turn or more from the fold has not crossed it.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "fold_chart.h"
#include "messages/pose_mapping.h"
#include "numeric/so3.h"
#include "safety.h"
#include "scene/scene.h"
#include "snap_ahead.h"

namespace snapthread {
namespace {

Scene LayoutScene(bool grip_direction, bool grip_rotation) {
  Scene scene;
  scene.grasp_layout.spatial_dimension = 3;
  scene.grasp_layout.grip_direction = grip_direction;
  scene.grasp_layout.grip_rotation = grip_rotation;
  scene.device.model_units_per_metre = 50.0;
  scene.device.model_origin = {7.0, 0.5, 1.0};
  scene.grasp_start = Vec::Zero(scene.grasp_layout.NumControls());
  scene.grasp_start.head(3) << 7.0, 0.5, 1.0;
  if (grip_direction) scene.grasp_start.segment(3, 3) << 1.0, 0.0, 0.0;
  return scene;
}

device::LocalModel DeviceModel(const server::PoseChartFold& f) {
  device::LocalModel m;
  m.has_fold = true;
  m.fold_id = 1;
  m.fold_curvature_per_m = f.curvature_per_m;
  m.has_fold_rotation = f.normal_r.squaredNorm() > 0.0;
  for (int i = 0; i < 3; ++i) {
    m.fold_point_m[i] = f.point_m[i];
    m.fold_normal[i] = f.normal[i];
    m.fold_normal_r[i] = f.normal_r[i];
  }
  for (int i = 0; i < 4; ++i) m.fold_q[i] = f.q[i];
  return m;
}

Eigen::Vector4d Wxyz(const Eigen::Quaterniond& q) { return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()); }

// The pose `offset` (3 metres, 3 radians of world-frame turn) from (p, R).
void Offset(const Eigen::Vector3d& p, const Eigen::Quaterniond& r, const Eigen::Matrix<double, 6, 1>& offset,
            Eigen::Vector3d* p_out, Eigen::Vector4d* q_out) {
  *p_out = p + offset.head<3>();
  Eigen::Quaterniond q(so3::Exp(offset.tail<3>()) * r.toRotationMatrix());
  *q_out = Wxyz(q.normalized());
}

// For each of the six pose directions e_i scaled by h, FoldSide against the controls'
// fold function g(u) = gradient . (u - u_fold); returns the largest deviation of
// FoldSide / g from their common ratio, relative to it, over the offsets where g is
// not tiny.
double ChartAgainstControls(const Scene& scene, const device::LocalModel& m, const Eigen::Vector3d& p_fold,
                            const Eigen::Quaterniond& r_fold, const Vec& u_fold, const Vec& gradient, double h) {
  const Eigen::Vector3d rest = messages::RestGripDirection(scene);
  std::vector<double> side, g;
  for (int i = 0; i < 6; ++i) {
    for (double sign : {1.0, -1.0}) {
      Eigen::Matrix<double, 6, 1> offset = Eigen::Matrix<double, 6, 1>::Zero();
      offset[i] = sign * (i < 3 ? h / scene.device.model_units_per_metre : h);
      Eigen::Vector3d p;
      Eigen::Vector4d q;
      Offset(p_fold, r_fold, offset, &p, &q);
      side.push_back(device::FoldSide(m, p.data(), q.data()));
      const Vec u = messages::PoseToControls(scene.device, scene.grasp_layout, p, q, rest);
      g.push_back(gradient.dot(u - u_fold));
    }
  }
  // The common ratio from the largest |g|.
  size_t k = 0;
  for (size_t i = 1; i < g.size(); ++i)
    if (std::abs(g[i]) > std::abs(g[k])) k = i;
  const double ratio = side[k] / g[k];
  EXPECT_GT(ratio, 0.0) << "the chart's past side is the controls' past side";
  double worst = 0.0;
  for (size_t i = 0; i < g.size(); ++i) {
    if (std::abs(g[i]) < 1e-3 * std::abs(g[k])) continue;
    worst = std::max(worst, std::abs(side[i] / (ratio * g[i]) - 1.0));
  }
  return worst;
}

TEST(FoldChartTest, GripDirectionBoundaryIsTheFoldFunctionToFirstOrderWhateverTheRoll) {
  const Scene scene = LayoutScene(true, false);
  // A fold at grip direction 30 degrees in the xy plane, found on the search's line off
  // the sphere (|u_d| = 1.3), with a gradient whose direction part is tangent (the model
  // sees u_d / |u_d|: n_d . u_d = 0).
  const Eigen::Vector3d d(std::cos(0.5236), std::sin(0.5236), 0.0);
  Vec u_fold(6), n(6);
  u_fold << 7.2, 0.4, 1.1, 1.3 * d;
  const Eigen::Vector3d n_d = Eigen::Vector3d(0.3, -0.2, 0.7) - d * d.dot(Eigen::Vector3d(0.3, -0.2, 0.7));
  n << 0.02, -0.05, 0.01, n_d;
  n.normalize();
  // The hand started 40 degrees before, rolled 70 degrees about its grip (a real
  // device's stylus roll; the sim-path hand's roll is zero).
  const Eigen::Vector3d d_start(std::cos(-0.1745), std::sin(-0.1745), 0.0);
  const Eigen::Quaterniond q_start = Eigen::Quaterniond(so3::Exp(1.2217 * d_start)) *
                                     Eigen::Quaterniond(so3::SmallestRotation(Eigen::Vector3d::UnitX(), d_start));
  Vec u_start(6);
  u_start << 7.1, 0.4, 1.1, d_start;
  server::PoseChartFold f;
  ASSERT_TRUE(server::FoldInPoseChart(scene, u_fold, n, 0.0, u_start, Wxyz(q_start), &f));
  EXPECT_NEAR(f.normal.squaredNorm() + f.normal_r.squaredNorm(), 1.0, 1e-12);
  EXPECT_NEAR(f.normal_r.dot(d), 0.0, 1e-12) << "a roll about the grip crosses nothing";
  // The hand at the fold: its orientation at the start turned to the fold's direction.
  const Eigen::Quaterniond r_fold(f.q[0], f.q[1], f.q[2], f.q[3]);
  EXPECT_LT((r_fold * Eigen::Vector3d::UnitX() - d).norm(), 1e-12) << "R_fold points the grip at the fold";
  const device::LocalModel m = DeviceModel(f);
  // The controls' fold function at unit directions: the model sees the direction, so its
  // gradient there is |u_d| n_d (d/d(u_d / |u_d|) = |u_d| d/du_d on the tangent).
  Vec gradient = n;
  gradient.tail(3) *= 1.3;
  // First order: the deviation falls with the offset (h, then h / 10).
  Vec u_unit = u_fold;
  u_unit.tail(3) = d;
  const double coarse = ChartAgainstControls(scene, m, f.point_m, r_fold, u_unit, gradient, 1e-3);
  const double fine = ChartAgainstControls(scene, m, f.point_m, r_fold, u_unit, gradient, 1e-4);
  // A hand that rolled on the way (about its grip, at the fold) is on the boundary there.
  const Eigen::Vector4d rolled = Wxyz(Eigen::Quaterniond(so3::Exp(0.3 * d) * r_fold.toRotationMatrix()));
  EXPECT_NEAR(device::FoldSide(m, f.point_m.data(), rolled.data()), 0.0, 1e-12);
  std::printf("grip direction: chart vs controls, relative deviation %.2e at 1e-3, %.2e at 1e-4\n", coarse, fine);
  EXPECT_LT(fine, 1e-3);
  EXPECT_LT(fine, 0.2 * coarse + 1e-9) << "the deviation is second order";
}

TEST(FoldChartTest, RodRotationVectorBoundaryIsTheFoldFunctionToFirstOrder) {
  const Scene scene = LayoutScene(false, true);
  Vec u_fold(6), n(6);
  u_fold << 7.3, 0.2, 0.9, 0.4, -1.1, 1.6;  // |phi| = 2 rad: J_l far from the identity
  n << 0.1, 0.3, -0.2, 0.5, 0.6, -0.4;
  n.normalize();
  server::PoseChartFold f;
  ASSERT_TRUE(server::FoldInPoseChart(scene, u_fold, n, 0.0, u_fold, Eigen::Vector4d(1, 0, 0, 0), &f));
  const Eigen::Quaterniond r_fold(f.q[0], f.q[1], f.q[2], f.q[3]);
  const device::LocalModel m = DeviceModel(f);
  const double coarse = ChartAgainstControls(scene, m, f.point_m, r_fold, u_fold, n, 1e-3);
  const double fine = ChartAgainstControls(scene, m, f.point_m, r_fold, u_fold, n, 1e-4);
  std::printf("rod: chart vs controls, relative deviation %.2e at 1e-3, %.2e at 1e-4\n", coarse, fine);
  EXPECT_LT(fine, 1e-3);
  EXPECT_LT(fine, 0.2 * coarse + 1e-9);
}

TEST(FoldChartTest, PositionalFoldIgnoresTurningAndATurnedFoldCountsWithinAQuarterTurn) {
  // curve2d-like: the normal in position only, the boundary as before.
  device::LocalModel m;
  m.has_fold = true;
  m.fold_normal[1] = 1.0;
  const double before[3] = {0.0, -0.001, 0.0}, past[3] = {0.0, 0.001, 0.0};
  const Eigen::Vector4d turned = Wxyz(Eigen::Quaterniond(so3::Exp(Eigen::Vector3d(0.0, 0.0, 2.5))));
  EXPECT_FALSE(device::PastFold(m, before, turned.data()));
  EXPECT_TRUE(device::PastFold(m, past, turned.data()));
  EXPECT_TRUE(device::PastFold(m, past, nullptr));

  // A fold reached by turning about +z at 6 degrees.
  device::LocalModel t;
  t.has_fold = true;
  t.has_fold_rotation = true;
  t.fold_normal_r[2] = 1.0;
  const Eigen::Vector4d at = Wxyz(Eigen::Quaterniond(so3::Exp(Eigen::Vector3d(0.0, 0.0, 0.1047))));
  for (int i = 0; i < 4; ++i) t.fold_q[i] = at[i];
  const double origin[3] = {0.0, 0.0, 0.0};
  auto past_at = [&](double degrees) {
    const Eigen::Vector4d q = Wxyz(Eigen::Quaterniond(so3::Exp(Eigen::Vector3d(0.0, 0.0, degrees * M_PI / 180.0))));
    return device::PastFold(t, origin, q.data());
  };
  EXPECT_FALSE(past_at(5.9));
  EXPECT_TRUE(past_at(6.1));
  EXPECT_TRUE(past_at(90.0));
  // A whole turn on, the same orientation: the device cannot tell turns apart (the
  // server drops a fold the hand passes without a snap, fold_boundary.h).
  EXPECT_TRUE(past_at(366.1));
  // More than a quarter turn past: the linear boundary says nothing there (log wraps at
  // half a turn, where the far side would read as the near one and back).
  EXPECT_FALSE(past_at(100.0));
  EXPECT_FALSE(past_at(185.0));
  EXPECT_FALSE(past_at(-100.0));
  // A device that senses no orientation is at rest: 6 degrees short.
  EXPECT_FALSE(device::PastFold(t, origin, nullptr));
}

}  // namespace
}  // namespace snapthread
