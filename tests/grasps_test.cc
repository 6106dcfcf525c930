// Many grasps (issue 15 items 2, 4, 7): the rod without a clamp held at both ends, the
// scene's grasps: list, force balance of two hands, the sweep's columns per grasp.
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "finite_difference.h"
#include "models/rod_model.h"
#include "rod_fixtures.h"
#include "scene/scene.h"
#include "sweep.h"
#include "test_util.h"
#include "tracking/make_tracker.h"

namespace snapthread {
namespace {

using V3 = Eigen::Vector3d;

using test_support::FreeRodParams;
using test_support::MaxRelativeError;

// Both grasps moved and turned, nodes and angles perturbed, lagged frames accepted at
// another perturbed state first: every derivative against central differences.
class FreeRodDerivatives : public ::testing::TestWithParam<int> {};

TEST_P(FreeRodDerivatives, MatchCentralDifferences) {
  const int n = GetParam();
  RodModel model(FreeRodParams(n));
  ASSERT_EQ(model.NumControls(), 12);
  std::mt19937 rng(77 + n);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  Vec u(12);
  u << 0.05, -0.1, 0.02, 0.3, -0.2, 0.4, 0.8, 0.2, -0.1, -0.3, 0.5, 0.9;
  Vec x = model.InitialState(u);
  const double l = 1.1 / n;
  auto perturb = [&](Vec* xs, Vec* us) {
    for (int i = 0; i < xs->size(); ++i) (*xs)[i] += 0.2 * l * d(rng);
    for (int c = 0; c < 12; ++c) (*us)[c] += 0.1 * d(rng);
  };
  perturb(&x, &u);
  model.AcceptState(x, u);
  perturb(&x, &u);
  const test_support::ModelDerivatives exact = test_support::ReportedDerivatives(model, x, u);
  const test_support::ModelDerivatives fd = test_support::CentralDifferences(model, x, u, 1e-6);
  EXPECT_LT(MaxRelativeError(exact.e_x, fd.e_x), 1e-6);
  EXPECT_LT(MaxRelativeError(exact.e_xx, fd.e_xx), 1e-6);
  EXPECT_LT(MaxRelativeError(exact.e_u, fd.e_u), 1e-6);
  EXPECT_LT(MaxRelativeError(exact.e_xu, fd.e_xu), 1e-6);
  EXPECT_LT(MaxRelativeError(exact.e_uu, fd.e_uu), 1e-6);
  // Both grasps take part: each half of E_u is non-zero.
  EXPECT_GT(exact.e_u.head(6).norm(), 1e-3);
  EXPECT_GT(exact.e_u.tail(6).norm(), 1e-3);
}

INSTANTIATE_TEST_SUITE_P(Sizes, FreeRodDerivatives, ::testing::Values(5, 9));

TEST(FreeRod, HeldEndsFollowTheirGrasps) {
  RodModel model(FreeRodParams(8));
  Vec u = Vec::Zero(12);
  u.head(3) = V3(0.1, 0.2, 0.3);
  u.segment(6, 3) = V3(1.0, 0.0, 0.0);
  Eigen::Matrix3Xd nodes;
  model.NodePositions(model.InitialState(u), u, &nodes);
  EXPECT_LT((nodes.col(0) - V3(0.1, 0.2, 0.3)).norm(), 1e-15);
  EXPECT_LT((nodes.col(8) - V3(1.0, 0.0, 0.0)).norm(), 1e-15);
  // Edge 0 leaves along the first grasp's x axis (R_start = clamp_rotation at φ = 0).
  const V3 t0 = (nodes.col(1) - nodes.col(0)) / (1.1 / 8);
  EXPECT_LT((t0 - FreeRodParams(8).clamp_rotation.col(0)).norm(), 1e-12);
}

const char* kTwoHands = R"(
model: rod
params: {n: 12, clamp: false}
grasps:
  - name: left
    edge: 0
    start: [0, 0, 0]
  - name: right
    edge: 11
    start: [0.9, 0, 0]
    path: [[0.9, 0, 0], {position: [0.7, 0.1, 0], rotation_deg: [0, 0, 30]}]
)";

TEST(SceneGrasps, NamesEveryGraspAndConcatenatesTheirControls) {
  const Scene s = ParseScene(kTwoHands, "two.yaml");
  ASSERT_EQ(s.grasps.size(), 2u);
  EXPECT_EQ(s.grasps[0].name, "left");
  EXPECT_EQ(s.grasps[1].holds, "edge 11");
  EXPECT_EQ(s.grasps[1].offset, 6);
  ASSERT_EQ(s.grasp_start.size(), 12);
  EXPECT_DOUBLE_EQ(s.grasp_start[6], 0.9);
  ASSERT_EQ(s.path.size(), 2u);
  // The left grasp has no path: it holds its start at every point.
  EXPECT_EQ(s.path[1].head(6), s.grasp_start.head(6));
  EXPECT_NEAR(s.path[1][11], 30.0 * std::numbers::pi / 180.0, 1e-15);
  EXPECT_EQ(FindGrasp(s, "right"), 1);
  EXPECT_EQ(FindGrasp(s, ""), 0);
  EXPECT_EQ(FindGrasp(s, "foot"), -1);
  // Old single-grasp scenes: one grasp, named "".
  const Scene old = testing::SceneFile("rod_greenhill.yaml");
  ASSERT_EQ(old.grasps.size(), 1u);
  EXPECT_EQ(old.grasps[0].name, "");
}

void ExpectSceneError(const std::string& yaml, const std::string& needle) {
  try {
    ParseScene(yaml, "bad.yaml");
    ADD_FAILURE() << "accepted: " << yaml;
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(SceneGrasps, RefusesGraspsThatDoNotMatchTheModel) {
  const std::string head = "model: rod\nparams: {n: 12, clamp: false}\n";
  ExpectSceneError(head + "grasp: {start: [1, 0, 0]}\n", "grasps:");
  ExpectSceneError(head + "grasps: [{name: a, edge: 0, start: [0, 0, 0]}]\n", "expected 2 grasps");
  ExpectSceneError(head + "grasps: [{name: a, edge: 11, start: [0, 0, 0]}, {name: b, edge: 0, start: [1, 0, 0]}]\n",
                   "grasps[0].edge: expected the edge 0");
  ExpectSceneError(head + "grasps: [{name: a, edge: 0, start: [0, 0, 0]}, {name: a, edge: 11, start: [1, 0, 0]}]\n",
                   "duplicated grasp name");
  ExpectSceneError(head + "grasps: [{name: a, edge: 0, start: [0, 0, 0], path: [[0, 0, 0]]},"
                          " {name: b, edge: 11, start: [1, 0, 0], path: [[1, 0, 0], [1, 1, 0]]}]\n",
                   "expected 1 points");
  ExpectSceneError(head + "grasps: [{name: a, node: 0, start: [0, 0, 0]}, {name: b, edge: 11, start: [1, 0, 0]}]\n",
                   "expected the edge 0");
  ExpectSceneError("model: rod\nparams: {n: 4, clamp: false}\n", "params.n");
  ExpectSceneError(head + "grasps: [{name: a, edge: -13, start: [0, 0, 0]}, {name: b, edge: -1, start: [1, 0, 0]}]\n",
                   "grasps[0].edge: -13 counts from the end past the first of 12 edges");
}

// edge: -1 is the last edge, whatever params.n is: the knot scene runs at another n with
// `--set params.n=...` alone.
TEST(SceneGrasps, NegativeEdgeCountsFromTheEnd) {
  const std::string two = "model: rod\nparams: {n: 12, clamp: false}\n"
                          "grasps: [{name: a, edge: 0, start: [0, 0, 0]}, {name: b, edge: -1, start: [1, 0, 0]}]\n";
  EXPECT_EQ(ParseScene(two, "two.yaml").grasps[1].holds, "edge 11");
  const Scene knot = testing::SceneFile("knot_overhand.yaml", {{"params.n", "100"}});
  ASSERT_EQ(knot.grasps.size(), 2u);
  EXPECT_EQ(knot.grasps[1].holds, "edge 99");
  EXPECT_EQ(testing::SceneFile("knot_overhand.yaml").grasps[1].holds, "edge 59");
}

// No clamp, no gravity: the rod is in equilibrium under the two hands alone, so their
// forces balance, f + f2 = 0, at every row of the knot path (the residual of the
// equilibrium is what is left).
TEST(TwoHands, ForcesBalanceWithoutAClamp) {
  const Scene scene = testing::SceneFile("knot_overhand.yaml");
  ASSERT_EQ(scene.grasps.size(), 2u);
  auto tracker = MakeTracker(scene);
  const auto rows = RunSweep(tracker.get(), PathControls(scene, 10));
  ASSERT_EQ(rows.size(), 10 * (scene.path.size() - 1) + 1);
  double fmax = 0.0;
  for (const SweepRow& r : rows) fmax = std::max({fmax, r.force.head(3).norm(), r.force.segment(6, 3).norm()});
  ASSERT_GT(fmax, 1.0);  // the path does load the hands
  for (const SweepRow& r : rows) {
    EXPECT_LE((r.force.head(3) + r.force.segment(6, 3)).norm(), 1e-5 * fmax) << "row " << r.step;
    EXPECT_NE(r.status, EquilibriumStatus::kFailed) << "row " << r.step;
  }
}

TEST(SweepCsv, AddsColumnsForTheSecondGrasp) {
  SweepRow row;
  row.u = Vec::LinSpaced(12, 1.0, 12.0);
  row.force = -row.u;
  row.state = Vec::Zero(1);
  std::ostringstream out;
  WriteSweepCsv({row}, "newton", out, GraspLayout{.spatial_dimension = 3, .grip_rotation = true}, 2);
  std::istringstream in(out.str());
  std::string header, line;
  std::getline(in, header);
  std::getline(in, line);
  EXPECT_NE(header.find(",negative_pivots,u2_x,u2_y,u2_z,f2_x,f2_y,f2_z"), std::string::npos) << header;
  EXPECT_EQ(header.rfind("step,u_x,u_y,u_z,f_x,f_y,f_z,", 0), 0u);
  EXPECT_NE(line.find(",7,8,9,-7,-8,-9"), std::string::npos) << line;
  EXPECT_EQ(line.rfind("0,1,2,3,-1,-2,-3,", 0), 0u) << line;
}

}  // namespace
}  // namespace snapthread
