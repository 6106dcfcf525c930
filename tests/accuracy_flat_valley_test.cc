// Flat valleys (docs/accuracy.md): a long thread slides far along its soft modes on one
// branch, converged and not snapped; a real fold crossing is still a snap; where round-off
// caps the accuracy the row says accuracy-limited.
#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "models/registry.h"
#include "scene/scene.h"
#include "sweep.h"
#include "tracking/make_tracker.h"
#include "tracking/tracker.h"

namespace snapthread {
namespace flat_valley_test {

// The accuracy issue's thread at n = 1000 (bending 2, stretching 200, unit segments):
// buckled by 1 unit, its lowest eigenvalue ~1e-12.
constexpr int kSegments = 1000;

ModelParams Thread() {
  ModelParams p;
  p.model = "thread3d";
  p.Set("n", kSegments);
  p.Set("segment_length", 1.0);
  p.Set("bending", 2.0);
  p.Set("stretching", 200.0);
  return p;
}

// The first `steps` rows of the path (0.999 n -> 0.97 n in 100 steps, with the
// small sideways move): each step compresses the buckle by 0.29.
std::vector<Vec> Path(int steps) {
  std::vector<Vec> us;
  for (int i = 0; i <= steps; ++i) {
    const double t = i / 100.0;
    Vec u(3);
    u << (0.999 + t * (0.97 - 0.999)) * kSegments, 0.5 + 0.3 * t, 0.2 * t;
    us.push_back(u);
  }
  return us;
}

// Default settings (force tolerance 1e-4 of the force scale): no row snapped although
// the state slides further per update than the snap threshold (the old rule called
// every such row snapped); every row an equilibrium; the converged ones certified to
// their tolerance and within 1e-3 of the force scale of a tighter run's force, and a row
// whose accuracy round-off caps says accuracy-limited.
TEST(FlatValley, LongSlideOnOneBranchIsConvergedNotSnapped) {
  const std::vector<Vec> us = Path(8);
  EquilibriumTracker tracker(MakeModel(Thread()), SolverOptions{});
  tracker.SetSnapThreshold(0.1);
  const std::vector<SweepRow> rows = RunSweep(&tracker, us);
  SolverOptions tight;
  tight.force_tolerance = 1e-6;
  tight.max_iterations = 0;
  EquilibriumTracker ref_tracker(MakeModel(Thread()), tight);
  const std::vector<SweepRow> ref = RunSweep(&ref_tracker, us);
  const double scale = tracker.model().ForceScale();
  double longest_slide = 0.0;
  size_t converged = 0;
  for (size_t i = 1; i < rows.size(); ++i) {
    const SweepRow& r = rows[i];
    EXPECT_NE(r.status, EquilibriumStatus::kSnapped) << "row " << i;
    EXPECT_FALSE(r.snapped) << "row " << i;
    EXPECT_TRUE(r.termination == Termination::kConverged || r.termination == Termination::kAccuracyLimited)
        << "row " << i;
    EXPECT_GE(r.force_error, 0.0) << "row " << i;
    if (r.termination == Termination::kConverged) {
      ++converged;
      EXPECT_LE(r.force_error, 1e-4 * scale) << "row " << i;
      EXPECT_LE((r.force - ref[i].force).lpNorm<Eigen::Infinity>(), 1e-3 * scale) << "row " << i;
    } else {
      EXPECT_GT(r.force_error, 1e-4 * scale) << "row " << i;
    }
    longest_slide = std::max(longest_slide, (r.state - rows[i - 1].state).lpNorm<Eigen::Infinity>());
  }
  EXPECT_GE(converged, (rows.size() - 1) / 2);
  EXPECT_GT(longest_slide, 1.0) << "the path should move the buckle far along its valley";
}

// A fold crossed (the strip of seed Fig 2.1 snapping between bent-up and bent-down) is
// still a snap: the followed minimum vanishes.
TEST(FlatValley, RealFoldCrossingIsStillSnapped) {
  const Scene scene = LoadScene(std::string(SNAPTHREAD_TEST_SOURCE_DIR) + "/scenes/curve2d_snap.yaml");
  auto tracker = MakeTracker(scene);
  const std::vector<SweepRow> rows = RunSweep(tracker.get(), PathControls(scene, 100));
  int snaps = 0;
  for (const SweepRow& r : rows) {
    snaps += r.status == EquilibriumStatus::kSnapped ? 1 : 0;
    EXPECT_NE(r.status, EquilibriumStatus::kFailed) << "row " << r.step;
  }
  // One snap each way (up-to-down past the mid-level, and back).
  EXPECT_GE(snaps, 2);
  EXPECT_LE(snaps, 4);
}

// A force tolerance far below what double precision can certify in this valley: the rows
// stop at the gradient's round-off and say accuracy-limited (usable, not failed), with the
// certified error above the tolerance.
TEST(FlatValley, RoundOffCappedAccuracyIsAccuracyLimited) {
  SolverOptions o;
  o.force_tolerance = 1e-9;
  EquilibriumTracker tracker(MakeModel(Thread()), o);
  const std::vector<SweepRow> rows = RunSweep(&tracker, Path(3));
  int limited = 0;
  for (const SweepRow& r : rows) {
    EXPECT_NE(r.status, EquilibriumStatus::kFailed) << "row " << r.step;
    if (r.termination != Termination::kAccuracyLimited) continue;
    ++limited;
    EXPECT_GT(r.force_error, o.force_tolerance * tracker.model().ForceScale()) << "row " << r.step;
  }
  EXPECT_GT(limited, 0);
}

}  // namespace flat_valley_test
}  // namespace snapthread
