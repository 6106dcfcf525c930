// The rod's scenes (issue 14, "Done when"): scenes/rod_greenhill.yaml run along its path
// (--path --steps 2000, as snapthread-sweep runs it) buckles at Greenhill's clamped-clamped
// twist, converging with n, halving when GJ doubles, with the torque GJ Φ / L before the
// buckle and the rod well out of line after it, under every registered method;
// scenes/rod_hockling.yaml throws a loop on the way out and loses it on the way back at a
// smaller twist; scenes/ribbon_flip.yaml flips over. And the sweep's rod columns.
// Measured values are printed (the report quotes them).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "sweep.h"
#include "test_util.h"

namespace snapthread {
namespace {

constexpr double kGreenhill = 8.9868;  // Φ_c GJ / EI, clamped-clamped, L = 1 (Greenhill 1883)

double Roll(const SweepRow& row) { return row.u[3]; }

std::vector<SweepRow> RunScene(const std::string& file, const std::vector<SceneOverride>& overrides,
                               int steps_per_leg) {
  const Scene scene = testing::SceneFile(file, overrides);
  auto tracker = MakeTracker(scene);
  return RunSweep(tracker.get(), PathControls(scene, steps_per_leg));
}

// The first row where the straight rod is unstable: a negative pivot of E_xx (the
// inertia; the solvers' λ_min estimate follows the twist mode and misses the bending
// pair that crosses zero), λ_min < 0, or the rod off its line (probe > 1e-4).
int FirstUnstableRow(const std::vector<SweepRow>& rows) {
  for (size_t i = 1; i < rows.size(); ++i) {
    const SweepRow& r = rows[i];
    if (r.negative_pivots > 0 || r.lambda_min < 0.0 || r.probe > 1e-4) return static_cast<int>(i);
  }
  return -1;
}

struct Greenhill {
  double critical_twist = -1.0;  // rad
  double torque_ratio = 0.0;     // t_x / (GJ Φ / L) at Φ_c / 2
  double final_probe = 0.0;
  int converged = 0;
  int rows = 0;
};

Greenhill RunGreenhill(const std::vector<SceneOverride>& overrides) {
  const std::vector<SweepRow> rows = RunScene("rod_greenhill.yaml", overrides, 2000);
  const Scene scene = testing::SceneFile("rod_greenhill.yaml", overrides);
  const double gj = scene.params.Number("twist_stiffness");
  const double length = scene.params.Number("length");
  Greenhill g;
  g.rows = static_cast<int>(rows.size());
  for (const SweepRow& r : rows) g.converged += r.termination == Termination::kConverged ? 1 : 0;
  g.final_probe = rows.back().probe;
  const int k = FirstUnstableRow(rows);
  if (k < 0) return g;
  g.critical_twist = Roll(rows[k]);
  const SweepRow& half = rows[k / 2];
  // The rod resists the roll: its torque on the hand is -GJ Φ / L about x (and, the
  // rotation vector staying on the x axis, equal to the rotation part of F = -E_u).
  EXPECT_NEAR(half.torque.x(), half.force[3], 1e-9 * std::abs(half.force[3]));
  g.torque_ratio = -half.torque.x() / (gj * Roll(half) / length);
  return g;
}

std::vector<SceneOverride> WithN(int n) { return {{"params.n", std::to_string(n)}}; }

// Φ_c → 8.9868 EI / GJ as n = 10 → 20 → 40 (error < 5 % at n = 40, shrinking), and the
// torque before the buckle is GJ Φ / L to within the discrete rod's n / (n - 1): the twist
// acts between the midpoints of the two held edges, (n - 1) ℓ apart.
TEST(RodGreenhillScene, CriticalTwistConvergesToGreenhillWithN) {
  double previous_error = 1.0;
  for (int n : {10, 20, 40}) {
    const Greenhill g = RunGreenhill(WithN(n));
    ASSERT_GT(g.critical_twist, 0.0) << "n=" << n << ": no buckle up to 720 degrees";
    const double error = std::abs(g.critical_twist / kGreenhill - 1.0);
    std::printf("rod_greenhill n=%d: Phi_c = %.4f rad (%.1f deg), error %.2f%%, torque / (GJ Phi / L) = %.4f\n",
                n, g.critical_twist, g.critical_twist * 180.0 / std::numbers::pi, 100.0 * error,
                g.torque_ratio);
    EXPECT_LT(error, previous_error) << "n=" << n;
    previous_error = error;
    EXPECT_NEAR(g.torque_ratio, n / (n - 1.0), 1e-4) << "n=" << n;
    if (n == 40) {
      EXPECT_NEAR(g.torque_ratio, 1.0, 0.03);
    }
  }
  EXPECT_LT(previous_error, 0.05);
}

TEST(RodGreenhillScene, CriticalTwistHalvesWhenTwistStiffnessDoubles) {
  const Greenhill soft = RunGreenhill({});
  const Greenhill stiff = RunGreenhill({{"params.twist_stiffness", "2.0"}});
  ASSERT_GT(soft.critical_twist, 0.0);
  ASSERT_GT(stiff.critical_twist, 0.0);
  const double ratio = stiff.critical_twist / soft.critical_twist;
  std::printf("rod_greenhill n=20: Phi_c(GJ=2) / Phi_c(GJ=1) = %.4f\n", ratio);
  EXPECT_NEAR(ratio, 0.5, 0.005);
}

// Item 4: every registered method follows the scene through the buckle, every update
// converges, and the rod ends clearly out of line.
class RodGreenhillMethodTest : public ::testing::TestWithParam<std::string> {};

TEST_P(RodGreenhillMethodTest, BucklesAndEndsOutOfLine) {
  const Greenhill g = RunGreenhill({{"solver.method", GetParam()}});
  ASSERT_GT(g.critical_twist, 0.0);
  EXPECT_NEAR(g.critical_twist / kGreenhill, 1.0, 0.05);
  EXPECT_GT(g.final_probe, 0.02);
  EXPECT_EQ(g.converged, g.rows);
}

INSTANTIATE_TEST_SUITE_P(Methods, RodGreenhillMethodTest,
                         ::testing::ValuesIn(SolverRegistry::Global().Names()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& c : name) c = c == '-' ? '_' : c;
                           return name;
                         });

// The tracker's Reset starts from a fresh rod: after two turns, a reset at roll 0 has no
// twist left (the model's turn count is forgotten), and a reset at 720 degrees holds the
// rod twisted by the grasp's angle modulo a turn, as a fresh model would.
TEST(RodGreenhillScene, ResetForgetsTheTurns) {
  const Scene scene = testing::SceneFile("rod_greenhill.yaml");
  auto tracker = MakeTracker(scene);
  const std::vector<Vec> path = PathControls(scene, 400);
  RunSweep(tracker.get(), path);
  ASSERT_GT(std::abs(tracker->last().force[3]), 1.0);  // twisted (and buckled)
  const TrackResult& r = tracker->Reset(path.front());
  EXPECT_LT(std::abs(r.force[3]), 1e-6);
  EXPECT_LT(r.probe, 1e-4);
}

// Hockling: a snap on the way out (roll increasing) and one on the way back, at rolls
// far apart (hysteresis), each a jump of the shape (the probe moves by > 0.01 over the
// snap's consecutive snapped rows: the fold row, then the landing).
TEST(RodHocklingScene, SnapsInOnTheWayOutAndOutOnTheWayBackElsewhere) {
  const std::vector<SweepRow> rows = RunScene("rod_hockling.yaml", {}, 300);
  std::vector<double> out, back;
  for (size_t i = 1; i < rows.size(); ++i) {
    if (!rows[i].snapped) continue;
    size_t last = i;
    while (last + 1 < rows.size() && rows[last + 1].snapped) ++last;
    const double roll_deg = Roll(rows[i]) * 180.0 / std::numbers::pi;
    std::printf("rod_hockling snap at rows %zu-%zu, roll %.1f deg, probe %.4f -> %.4f, t_x %.3f -> %.3f\n", i,
                last, roll_deg, rows[i - 1].probe, rows[last].probe, rows[i - 1].torque.x(), rows[last].torque.x());
    EXPECT_GT(std::abs(rows[last].probe - rows[i - 1].probe), 0.01) << "row " << i;
    (Roll(rows[i]) > Roll(rows[i - 1]) ? out : back).push_back(roll_deg);
    i = last;
  }
  ASSERT_FALSE(out.empty()) << "no loop snapped in on the way out";
  ASSERT_FALSE(back.empty()) << "no loop snapped out on the way back";
  EXPECT_GT(out.front() - back.back(), 90.0);
}

// The ribbon (B2 = 10 B1) flips over once on the way out and once on the way back, at
// different rolls, and every update converges.
TEST(RibbonFlipScene, FlipsOverEachWayAndConverges) {
  const std::vector<SweepRow> rows = RunScene("ribbon_flip.yaml", {}, 360);
  int out = 0, back = 0;
  double out_roll = 0.0, back_roll = 0.0;
  for (size_t i = 1; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].termination, Termination::kConverged) << "row " << i;
    if (!rows[i].snapped) continue;
    const bool outward = Roll(rows[i]) > Roll(rows[i - 1]);
    (outward ? out : back) += 1;
    (outward ? out_roll : back_roll) = Roll(rows[i]) * 180.0 / std::numbers::pi;
  }
  std::printf("ribbon_flip: %d flip(s) out (last at %.1f deg), %d back (last at %.1f deg)\n", out, out_roll,
              back, back_roll);
  EXPECT_GE(out, 1);
  EXPECT_GE(back, 1);
  EXPECT_GT(std::abs(out_roll - back_roll), 10.0);
}

// The CSV of a rod scene ends with roll_deg, t_x, t_y, t_z, negative_pivots (then the
// last column of every sweep, force_error); the torque is the rotation part of F (a pure
// roll) and roll_deg the roll in degrees.
TEST(RodSweepCsv, RodScenesAddRollAndTorqueColumns) {
  const Scene scene = testing::SceneFile("rod_greenhill.yaml", WithN(6));
  auto tracker = MakeTracker(scene);
  const std::vector<SweepRow> rows = RunSweep(tracker.get(), PathControls(scene, 4));
  std::ostringstream csv;
  WriteSweepCsv(rows, scene.solver.method, csv, scene.grasp_layout);
  std::istringstream in(csv.str());
  std::string header, line, last;
  std::getline(in, header);
  EXPECT_NE(header.find(",hessian_evals,roll_deg,t_x,t_y,t_z,negative_pivots"), std::string::npos) << header;
  while (std::getline(in, line)) last = line;
  std::vector<double> cells;
  std::istringstream fields(last);
  for (std::string cell; std::getline(fields, cell, ',');) cells.push_back(std::atof(cell.c_str()));
  ASSERT_GE(cells.size(), 6u);
  const size_t c = cells.size() - 6;
  EXPECT_NEAR(cells[c], 720.0, 1e-9);
  EXPECT_NEAR(cells[c + 1], rows.back().force[3], 1e-9 * std::max(1.0, std::abs(rows.back().force[3])));
  // Other scenes keep their columns.
  std::ostringstream plain;
  WriteSweepCsv(rows, scene.solver.method, plain);
  EXPECT_EQ(plain.str().find("roll_deg"), std::string::npos);
}

}  // namespace
}  // namespace snapthread
