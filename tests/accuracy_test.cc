// Certified forces (docs/accuracy.md): convergence to round-off is "converged", the
// certified force error bounds the true one against a round-off-polished reference, and
// the default stopping rule holds the force to its tolerance of the force scale.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "accuracy_matrix.h"
#include "models/models.h"
#include "models/registry.h"
#include "sweep.h"
#include "tracking/tracker.h"

namespace snapthread {
namespace accuracy_test {

// The thread: n unit segments, bending 2, stretching 200.
ModelParams Thread(int n) {
  ModelParams p;
  p.model = "thread3d";
  p.Set("n", n);
  p.Set("segment_length", 1.0);
  p.Set("bending", 2.0);
  p.Set("stretching", 200.0);
  return p;
}

// The grasp pulled from 0.999 n to 0.97 n along x with a small sideways move.
std::vector<Vec> Path(int n, int steps) {
  std::vector<Vec> us;
  for (int i = 0; i <= steps; ++i) {
    const double t = static_cast<double>(i) / steps;
    Vec u(3);
    u << (0.999 + t * (0.97 - 0.999)) * n, 0.5 + 0.3 * t, 0.2 * t;
    us.push_back(u);
  }
  return us;
}

// The exact equilibrium next to x: damped Newton steps to round-off with the model and a
// linear solver only (PolishToRoundOff, tools/accuracy_matrix.h).
Vec Polish(const Model& model, const Vec& u, const Vec& x) { return PolishToRoundOff(model, u, x); }

struct Row {
  SolverSummary summary;
  double true_error = 0.0;  // |F - F_ref|_inf, model force units
};

// Tracks the path with `options` and measures every row's force against the polished
// reference next to it.
std::vector<Row> TrackAndMeasure(int n, int steps, const SolverOptions& options) {
  EquilibriumTracker tracker(MakeModel(Thread(n)), options);
  tracker.SetSnapThreshold(0.1);
  const Model& model = tracker.model();
  std::vector<Row> rows;
  const std::vector<Vec> us = Path(n, steps);
  for (size_t i = 0; i < us.size(); ++i) {
    const TrackResult& r = i == 0 ? tracker.Reset(us[i]) : tracker.Update(us[i]);
    const Vec ref = Polish(model, us[i], tracker.state());
    Vec eu;
    model.ControlGradient(ref, us[i], &eu);
    rows.push_back({r.summary, (r.force + eu).lpNorm<Eigen::Infinity>()});
  }
  return rows;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// The reference of issue 26 (cutoff 1e-11, below the gradient's round-off at n = 100):
// every row reaches round-off and says "converged", none "failed".
TEST(Accuracy, ConvergenceToRoundOffIsConverged) {
  SolverOptions o;
  o.cutoff = 1e-11;
  o.force_tolerance = 0.0;  // the cutoff alone, as an explicit --cutoff
  o.max_iterations = 50;
  const std::vector<Row> rows = TrackAndMeasure(100, 50, o);
  int at_round_off = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const SolverSummary& s = rows[i].summary;
    EXPECT_EQ(s.termination, Termination::kConverged) << "row " << i << ": " << s.BriefReport();
    EXPECT_NE(s.status, EquilibriumStatus::kFailed) << "row " << i << ": " << s.BriefReport();
    EXPECT_NE(s.status, EquilibriumStatus::kSnapped) << "row " << i << ": " << s.BriefReport();
    if (s.at_round_off) {
      ++at_round_off;
      EXPECT_GE(s.residual, o.cutoff) << "row " << i;
      EXPECT_LE(s.residual, s.round_off_floor) << "row " << i;
    }
  }
  // The cutoff is below round-off here: the round-off test is what ended most rows.
  EXPECT_GT(at_round_off, 0);
}

// The certified error bounds the true one at the old absolute cutoff, where the force
// is far from exact at n = 100 (up to 0.37 % of the force scale before this change).
TEST(Accuracy, ForceErrorEstimateBoundsTheTrueError) {
  SolverOptions o;
  o.force_tolerance = 0.0;  // |E_x| < 1e-6 alone: errors worth bounding
  const std::vector<Row> rows = TrackAndMeasure(100, 20, o);
  const double scale = MakeModel(Thread(100))->ForceScale();
  int covered = 0, measured = 0;
  std::vector<double> ratios;
  for (size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    ASSERT_GE(r.summary.force_error, 0.0) << "row " << i << ": " << r.summary.BriefReport();
    ++measured;
    if (r.summary.force_error >= r.true_error) ++covered;
    // The ratio only where the true error is above the reference's own round-off.
    if (r.true_error > 1e-12 * scale) ratios.push_back(r.summary.force_error / r.true_error);
  }
  EXPECT_GE(covered, measured * 99 / 100) << covered << " of " << measured << " rows covered";
  if (!ratios.empty()) {
    EXPECT_LE(Median(ratios), 10.0);
  }
}

// By default a solve stops on the force: every row within its tolerance of the force
// scale against the polished reference.
TEST(Accuracy, DefaultStopsOnTheForce) {
  SolverOptions o;  // force_tolerance 1e-4 of the force scale
  const std::vector<Row> rows = TrackAndMeasure(100, 20, o);
  const double scale = MakeModel(Thread(100))->ForceScale();
  for (size_t i = 0; i < rows.size(); ++i) {
    const SolverSummary& s = rows[i].summary;
    EXPECT_TRUE(s.IsConverged()) << "row " << i << ": " << s.BriefReport();
    EXPECT_NEAR(s.force_target, 1e-4 * scale, 1e-12 * scale);
    EXPECT_LE(rows[i].true_error, 1e-4 * scale) << "row " << i << ": " << s.BriefReport();
    if (s.termination == Termination::kConverged) {
      EXPECT_LE(s.force_error, s.force_target) << "row " << i;
    }
  }
}

// The sweep CSV ends with the certified force error of each row.
TEST(Accuracy, SweepCsvEndsWithTheForceError) {
  EquilibriumTracker tracker(MakeModel(Thread(10)), SolverOptions{});
  const std::vector<SweepRow> rows = RunSweep(&tracker, Path(10, 3));
  std::ostringstream csv;
  WriteSweepCsv(rows, "higher-order", csv, GraspLayout{.spatial_dimension = 3}, 1, 17);
  std::istringstream in(csv.str());
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header.substr(header.rfind(',') + 1), "force_error") << header;
  for (const SweepRow& r : rows) {
    ASSERT_TRUE(std::getline(in, line));
    EXPECT_GE(r.force_error, 0.0) << "row " << r.step;
    EXPECT_EQ(std::stod(line.substr(line.rfind(',') + 1)), r.force_error) << line;
  }
}

TEST(Accuracy, ForceToleranceOptionsAreChecked) {
  SolverOptions o;
  std::string why;
  EXPECT_TRUE(o.IsValid(&why)) << why;
  o.force_tolerance = -1e-4;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("solver.force_tolerance"), std::string::npos) << why;
  o.force_tolerance = 0.0;  // the cutoff alone
  EXPECT_TRUE(o.IsValid(&why)) << why;
  o.force_floor_n = -1.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("solver.force_floor_n"), std::string::npos) << why;
}

}  // namespace accuracy_test
}  // namespace snapthread
