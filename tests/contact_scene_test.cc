// Self-contact along paths (issue 15 item 7): a rod twisted against itself
// (scenes/rod_hockling.yaml with contact on and params.radius set) wraps round itself
// without its centreline passing through: at every row, under every method, no two
// segments more than 2r apart along the rod come closer than 2r (less 2% of r).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "models/rod_model.h"
#include "solvers/registry.h"
#include "sweep.h"
#include "test_util.h"

namespace snapthread {
namespace {

struct ContactRun {
  double min_gap_ratio = 1e300;  // min over rows of (closest distance) / 2r
  int max_active = 0;
  int failed = 0;
  int snapped = 0;
};

ContactRun RunWithContact(const Scene& scene, const std::vector<Vec>& controls, double radius) {
  auto tracker = MakeTracker(scene);
  ContactRun run;
  Eigen::Matrix3Xd nodes;
  auto check = [&](const TrackResult& res) {
    const Model& m = tracker->model();
    m.NodePositions(tracker->state(), tracker->control(), &nodes);
    // The pairs: more than 2r apart along the rod, (j - i - 1) ℓ > 2r.
    const double ell = (nodes.col(1) - nodes.col(0)).norm();
    const int segments = static_cast<int>(nodes.cols()) - 1;
    int gap = 2;
    while ((gap - 1) * ell <= 2 * radius) ++gap;
    double closest = 1e300;
    for (int i = 0; i < segments; ++i) {
      for (int j = i + gap; j < segments; ++j) {
        closest = std::min(closest, std::sqrt(contact::ClosestPoints(nodes.col(i), nodes.col(i + 1),
                                                                     nodes.col(j), nodes.col(j + 1))
                                                  .distance_sq));
      }
    }
    run.min_gap_ratio = std::min(run.min_gap_ratio, closest / (2 * radius));
    run.max_active = std::max(run.max_active, static_cast<int>(tracker->ActiveContacts().size()));
    run.failed += res.summary.termination == Termination::kLinearSolverFailed ? 1 : 0;
    run.snapped += res.snapped ? 1 : 0;
  };
  check(tracker->Reset(scene.grasp_start));
  for (const Vec& u : controls) check(tracker->Update(u));
  return run;
}

std::vector<SceneOverride> HocklingContact() {
  return {{"params.contact", "true"},
          {"params.radius", "0.01"},
          {"params.contact_distance", "0.005"},
          {"params.contact_stiffness", "0.01"}};
}

class RodHocklingContactTest : public ::testing::TestWithParam<std::string> {};

TEST_P(RodHocklingContactTest, WrapsAroundItselfWithoutCrossing) {
  std::vector<SceneOverride> o = HocklingContact();
  o.push_back({"solver.method", GetParam()});
  const Scene scene = testing::SceneFile("rod_hockling.yaml", o);
  const ContactRun run = RunWithContact(scene, PathControls(scene, 300), 0.01);
  std::printf("rod_hockling + contact, %s: min distance / 2r = %.4f, max active pairs %d, "
              "snapped rows %d, failed rows %d\n",
              GetParam().c_str(), run.min_gap_ratio, run.max_active, run.snapped, run.failed);
  EXPECT_GE(run.min_gap_ratio, 1.0 - 0.01);  // 2r (1 - 0.02 r / 2r)
  EXPECT_GT(run.max_active, 0) << "the rod never met itself: the test tests nothing";
}

INSTANTIATE_TEST_SUITE_P(Methods, RodHocklingContactTest,
                         ::testing::ValuesIn(SolverRegistry::Global().Names()));

}  // namespace
}  // namespace snapthread
