// Issue 15's "Done when" for the knot, as a user runs it:
//   snapthread-sweep --scene scenes/knot_overhand.yaml --path --steps 100 --shapes-out shapes.csv
// ties a real overhand knot (unknot at the first row, trefoil at the last: IdentifyKnot of
// the rod closed far away), no two segments more than 2r apart along the rod come closer
// than 2r (beyond 2% of r) at any row, and the two hands' forces balance at every row.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "scene/scene.h"
#include "test_support.h"
#include "test_util.h"
#include "topology/identify_knot.h"

namespace snapthread {
namespace {

using V3 = Eigen::Vector3d;

// Closest distance between the segments [p0, p1] and [q0, q1] (clamped closest points).
double SegmentDistance(const V3& p0, const V3& p1, const V3& q0, const V3& q1) {
  const V3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r), c = d1.dot(r), b = d1.dot(d2);
  const double den = a * e - b * b;
  double s = den > 1e-14 * a * e ? std::clamp((b * f - c * e) / den, 0.0, 1.0) : 0.0;
  double t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1.0) {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
  return (p0 + s * d1 - q0 - t * d2).norm();
}

struct KnotRun {
  std::map<int, std::vector<V3>> shapes;           // step -> nodes
  std::vector<std::map<std::string, double>> rows;  // sweep CSV, numeric columns
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
    for (std::string v; std::getline(ls, v, ',') && k < names.size(); ++k) row[names[k]] = std::atof(v.c_str());
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

TEST_F(KnotOverhand, StartsUnknottedAndEndsInATrefoil) {
  ASSERT_FALSE(run_->shapes.empty());
  const topology::KnotInfo first = topology::IdentifyKnot(run_->shapes.begin()->second);
  const topology::KnotInfo last = topology::IdentifyKnot(run_->shapes.rbegin()->second);
  ASSERT_TRUE(first.ok) << first.error;
  ASSERT_TRUE(last.ok) << last.error;
  EXPECT_EQ(first.name, "unknot");
  EXPECT_EQ(last.name, "trefoil") << "determinant " << last.determinant;
}

TEST_F(KnotOverhand, NoSegmentsInterpenetrate) {
  const Scene scene = testing::SceneFile("knot_overhand.yaml");
  const double r = scene.params.Number("radius"), l = scene.params.Number("length") / scene.params.Integer("n");
  double closest = 1e300;
  int at = -1;
  for (const auto& [step, p] : run_->shapes) {
    const int n = static_cast<int>(p.size()) - 1;
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        if ((j - i - 1) * l <= 2.0 * r) continue;  // neighbours along the rod
        const double d = SegmentDistance(p[i], p[i + 1], p[j], p[j + 1]);
        if (d < closest) {
          closest = d;
          at = step;
        }
      }
    }
  }
  std::printf("knot_overhand: closest approach %.5f (2r = %.5f) at row %d\n", closest, 2 * r, at);
  EXPECT_GE(closest, 2.0 * r * (1.0 - 0.02)) << "row " << at;
}

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

}  // namespace
}  // namespace snapthread
