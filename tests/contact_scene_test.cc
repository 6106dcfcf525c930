// Self-contact along paths (issue 15 item 7): a rod twisted against itself
// (scenes/rod_hockling.yaml with contact on and params.radius set) wraps round itself
// without its centreline passing through: at every row, under every method, no two
// segments more than 2r apart along the rod come closer than 2r (less 2% of r).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "models/contact_terms.h"
#include "models/registry.h"
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

// Issue 15 item 8: E_xx's pattern is the rod's band plus the blocks of the segment pairs
// near contact, changed (and re-analysed) only when that set changes. Along the knot
// path (scenes/knot_overhand.yaml, 100 steps a leg), at every 8th row:
//  * the inertia the solver reports (the fold detection's) is the Hessian's (Sylvester's
//    law: the number of negative eigenvalues of the dense matrix);
//  * a fresh model's pattern at that state is the band plus at most one 12 x 12 block
//    per pair within the set's reach (1 + margin) (2r + d-hat): sparse, not every pair
//    that may ever touch.
TEST(KnotPathPattern, InertiaIsTheDenseHessiansAndThePatternOnlyHasThePairsNearContact) {
  const Scene scene = testing::SceneFile("knot_overhand.yaml");
  auto tracker = MakeTracker(scene);
  const std::vector<Vec> controls = PathControls(scene, 100);
  const double reach = (1.0 + internal::ContactTerms::kMargin) *
                       (2.0 * scene.params.Number("radius") + scene.params.Number("contact_distance"));
  int checked = 0, max_pairs = 0;
  long max_nonzeros = 0;
  std::vector<std::pair<int, int>> near;
  Eigen::Matrix3Xd nodes;
  auto check = [&](const TrackResult& res) {
    ASSERT_TRUE(res.summary.IsConverged()) << res.summary.message;
    const Model& m = tracker->model();
    SparseMatrix h;
    m.Hessian(tracker->state(), tracker->control(), &h);
    const Mat dense = Mat(h);
    const Eigen::SelfAdjointEigenSolver<Mat> eig(dense, Eigen::EigenvaluesOnly);
    int negative = 0;
    for (int k = 0; k < dense.rows(); ++k) negative += eig.eigenvalues()[k] < 0.0 ? 1 : 0;
    EXPECT_EQ(res.summary.negative_pivots, negative) << "row " << checked;

    auto fresh = MakeModel(scene.params);
    const long band = fresh->HessianPattern().nonZeros();
    fresh->Hessian(tracker->state(), tracker->control(), &h);
    fresh->NodePositions(tracker->state(), tracker->control(), &nodes);
    dynamic_cast<const RodModel&>(*fresh).self_contact().PairsWithin(nodes, reach, &near);
    EXPECT_LE(h.nonZeros(), band + 144L * static_cast<long>(near.size())) << "row " << checked;
    max_pairs = std::max(max_pairs, static_cast<int>(near.size()));
    max_nonzeros = std::max(max_nonzeros, static_cast<long>(h.nonZeros()));
    ++checked;
  };
  check(tracker->Reset(scene.grasp_start));
  for (size_t k = 0; k < controls.size(); ++k) {
    const TrackResult& res = tracker->Update(controls[k]);
    if (k % 8 == 7) check(res);
  }
  const long n = tracker->model().NumStates();
  std::printf("knot path: %d rows checked, up to %d pairs near contact, pattern up to %ld non-zeros of %ld\n",
              checked, max_pairs, max_nonzeros, n * n);
  EXPECT_GT(max_pairs, 0) << "the rod never met itself: the test tests nothing";
}

}  // namespace
}  // namespace snapthread
