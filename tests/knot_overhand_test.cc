// Issue 15's "Done when" for the knot, as a user runs it:
//   snapthread-sweep --scene scenes/knot_overhand.yaml --path --steps 100 --shapes-out shapes.csv
// ties a real overhand knot (unknot at the first row, trefoil at the last: IdentifyKnot of
// the rod closed far away), no two segments more than 2r apart along the rod come closer
// than 2r (beyond 2% of r) at any row, and the two hands' forces balance at every row.
// The scene's suture has coil memory (natural_curvature); docs/models-rod.md.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "scene/scene.h"
#include "test_support.h"
#include "test_util.h"
#include "contact/segment_distance.h"
#include "topology/identify_knot.h"

namespace snapthread {
namespace {

using V3 = Eigen::Vector3d;

struct KnotRun {
  std::map<int, std::vector<V3>> shapes;           // step -> nodes
  std::vector<std::map<std::string, double>> rows;  // sweep CSV, numeric columns
  std::vector<std::string> terminations;            // sweep CSV, the solver's termination
};

KnotRun SweepKnot(const test_support::ScopedTempDir& dir) {
  const std::string shapes = dir.path() + "/shapes.csv", out = dir.path() + "/sweep.csv";
  test_support::ChildProcess sweep(
      {testing::BinDir() + "/snapthread-sweep", "--scene", testing::SourceDir() + "/scenes/knot_overhand.yaml",
       "--path", "--steps", "100", "--shapes-out", shapes, "--out", out},
      test_support::OneLog(dir.path() + "/log.txt"));
  int code = -1;
  sweep.WaitOrKill(600.0, &code);
  EXPECT_EQ(code, 0) << sweep.Out();
  KnotRun run;
  std::ifstream s(shapes);
  std::string line;
  std::getline(s, line);
  EXPECT_EQ(line, "step,node,x,y,z");
  while (std::getline(s, line)) {
    int step = 0, node = 0;
    double x = 0, y = 0, z = 0;
    if (std::sscanf(line.c_str(), "%d,%d,%lf,%lf,%lf", &step, &node, &x, &y, &z) != 5) continue;
    run.shapes[step].push_back(V3(x, y, z));
  }
  std::ifstream c(out);
  std::getline(c, line);
  std::vector<std::string> names;
  std::stringstream hs(line);
  for (std::string n; std::getline(hs, n, ',');) names.push_back(n);
  while (std::getline(c, line)) {
    std::stringstream ls(line);
    std::map<std::string, double> row;
    size_t k = 0;
    for (std::string v; std::getline(ls, v, ',') && k < names.size(); ++k) {
      row[names[k]] = std::atof(v.c_str());
      if (names[k] == "termination") run.terminations.push_back(v);
    }
    run.rows.push_back(row);
  }
  return run;
}

class KnotOverhand : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test_support::ScopedTempDir("knot_overhand");
    run_ = new KnotRun(SweepKnot(*dir_));
  }
  static void TearDownTestSuite() {
    delete run_;
    delete dir_;
  }
  static test_support::ScopedTempDir* dir_;
  static KnotRun* run_;
};
test_support::ScopedTempDir* KnotOverhand::dir_ = nullptr;
KnotRun* KnotOverhand::run_ = nullptr;

TEST_F(KnotOverhand, EveryRowHasTheRodAndBothHands) {
  const Scene scene = testing::SceneFile("knot_overhand.yaml");
  const int legs = static_cast<int>(scene.path.size()) - 1;
  EXPECT_EQ(run_->rows.size(), static_cast<size_t>(100 * legs + 1));
  ASSERT_EQ(run_->shapes.size(), run_->rows.size());
  for (const auto& [step, nodes] : run_->shapes) ASSERT_EQ(nodes.size(), 61u) << "step " << step;
  ASSERT_FALSE(run_->rows.empty());
  EXPECT_TRUE(run_->rows.front().count("f2_z"));
}

// The pairs: segments i < j more than 2r apart along the rod, (j - i - 1) ℓ > 2r.
// Returns the smallest centreline distance over them, and the pair.
double ClosestApproach(const std::vector<V3>& nodes, double radius, int* seg_a, int* seg_b) {
  const int segments = static_cast<int>(nodes.size()) - 1;
  double ell = 0.0;
  for (int k = 0; k < segments; ++k) ell += (nodes[k + 1] - nodes[k]).norm();
  ell /= segments;
  int gap = 2;
  while ((gap - 1) * ell <= 2.0 * radius) ++gap;
  double closest = 1e300;
  for (int i = 0; i < segments; ++i) {
    for (int j = i + gap; j < segments; ++j) {
      const double d = std::sqrt(contact::ClosestPoints(nodes[i], nodes[i + 1], nodes[j], nodes[j + 1]).distance_sq);
      if (d < closest) closest = d, *seg_a = i, *seg_b = j;
    }
  }
  return closest;
}

TEST_F(KnotOverhand, StartsUnknotted) {
  ASSERT_FALSE(run_->shapes.empty());
  const topology::KnotInfo first = topology::IdentifyKnot(run_->shapes.begin()->second);
  ASSERT_TRUE(first.ok) << first.error;
  EXPECT_EQ(first.name, "unknot");
  EXPECT_EQ(first.determinant, 1);
}

// The barrier: no two segments more than 2r apart along the rod come closer than 2r, less
// 2% of r (the bound), at any row; and the rod does meet itself (else this tests
// nothing).
TEST_F(KnotOverhand, SegmentsNeverCloserThanTwiceTheRadius) {
  const Scene scene = testing::SceneFile("knot_overhand.yaml");
  const double r = scene.params.Number("radius");
  ASSERT_TRUE(scene.params.Bool("contact"));
  const double activation = 2.0 * r + scene.params.Number("contact_distance");
  double closest = 1e300;
  for (const auto& [step, nodes] : run_->shapes) {
    int a = -1, b = -1;
    const double d = ClosestApproach(nodes, r, &a, &b);
    closest = std::min(closest, d);
    EXPECT_GE(d, 2.0 * r - 0.02 * r) << "step " << step << ": segments " << a << " and " << b;
  }
  std::printf("knot_overhand: closest approach %.6f = %.4f x 2r\n", closest, closest / (2.0 * r));
  EXPECT_LT(closest, activation) << "no pair ever came within the barrier's reach";
}
// The last row, closed far away, is the overhand knot: the trefoil.
TEST_F(KnotOverhand, EndsInATrefoil) {
  ASSERT_FALSE(run_->shapes.empty());
  const topology::KnotInfo last = topology::IdentifyKnot(run_->shapes.rbegin()->second);
  ASSERT_TRUE(last.ok) << last.error;
  EXPECT_EQ(last.determinant, 3) << last.name;  // |Δ(-1)| of the trefoil
  // Δ(t) = 1 - t + t² (up to units ±t^k).
  EXPECT_EQ(last.alexander, (std::vector<std::int64_t>{1, -1, 1})) << last.name;
  EXPECT_EQ(last.name, "trefoil");
}

// A free rod with no gravity: the two hands' forces balance at every row, |f + f2| within
// 1e-5 of the largest |f| (the bound; a row the solver leaves unconverged shows
// its residual here).
TEST_F(KnotOverhand, HandsForcesBalance) {
  double fmax = 0.0;
  auto f = [](const std::map<std::string, double>& row, const char* p) {
    return V3(row.at(std::string(p) + "_x"), row.at(std::string(p) + "_y"), row.at(std::string(p) + "_z"));
  };
  for (const auto& row : run_->rows) fmax = std::max({fmax, f(row, "f").norm(), f(row, "f2").norm()});
  ASSERT_GT(fmax, 0.0);
  for (size_t k = 0; k < run_->rows.size(); ++k)
    EXPECT_LE((f(run_->rows[k], "f") + f(run_->rows[k], "f2")).norm(), 1e-5 * fmax) << "row " << k;
}

// Every row is an equilibrium: the solver converged (snaps included), none ran out of
// iterations or failed in its linear solver.
TEST_F(KnotOverhand, EveryRowConverges) {
  ASSERT_EQ(run_->terminations.size(), run_->rows.size());
  for (size_t k = 0; k < run_->terminations.size(); ++k)
    EXPECT_EQ(run_->terminations[k], "converged") << "row " << k;
}

}  // namespace
}  // namespace snapthread
