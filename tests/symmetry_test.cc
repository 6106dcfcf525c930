// Symmetries (issue 13, item 1): a free thread3d whose grasp crosses the clamp axis,
// where the roll about the clamp–grasp axis is a null direction of E_xx and, just past
// it, the buckle rolls half a turn. Every method that refuses saddles converges every
// row in a few iterations; the force and stiffness are those of the same equilibria
// found without the symmetry (the orbit search only changes the way there); and no
// shipped scene or stability case ends with a failed linear solver.
#include <memory>

#include <gtest/gtest.h>

#include "models/registry.h"
#include "models/symmetry_capability.h"
#include "sweep.h"
#include "test_util.h"

namespace snapthread {
namespace {

std::vector<SweepRow> AxisSweep(const std::string& method) {
  Scene scene = testing::SceneFile("thread3d_axis_cross.yaml");
  scene.solver.method = method;
  return RunSweep(MakeTracker(scene).get(), PathControls(scene, 200));
}

// The thread3d model with its symmetry hidden (symmetry() stays null): what the solvers
// saw before.
class WithoutSymmetries final : public Model {
 public:
  explicit WithoutSymmetries(std::unique_ptr<Model> m) : m_(std::move(m)) {}
  std::string_view Name() const override { return m_->Name(); }
  int NumStates() const override { return m_->NumStates(); }
  int NumControls() const override { return m_->NumControls(); }
  int SpatialDimension() const override { return m_->SpatialDimension(); }
  double Energy(const Vec& x, const Vec& u) const override { return m_->Energy(x, u); }
  void Gradient(const Vec& x, const Vec& u, Vec* g) const override { m_->Gradient(x, u, g); }
  const SparseMatrix& HessianPattern() const override { return m_->HessianPattern(); }
  void Hessian(const Vec& x, const Vec& u, SparseMatrix* h) const override { m_->Hessian(x, u, h); }
  void ControlGradient(const Vec& x, const Vec& u, Vec* eu) const override { m_->ControlGradient(x, u, eu); }
  void MixedHessian(const Vec& x, const Vec& u, Mat* exu) const override { m_->MixedHessian(x, u, exu); }
  void ControlHessian(const Vec& x, const Vec& u, Mat* euu) const override { m_->ControlHessian(x, u, euu); }
  Vec InitialState(const Vec& u) const override { return m_->InitialState(u); }
  void NodePositions(const Vec& x, const Vec& u, Eigen::Matrix3Xd* n) const override { m_->NodePositions(x, u, n); }
  double Probe(const Vec& x, const Vec& u) const override { return m_->Probe(x, u); }
  double ForceScale() const override { return m_->ForceScale(); }
  int HessianBandwidth() const override { return m_->HessianBandwidth(); }

 private:
  std::unique_ptr<Model> m_;
};

TEST(Symmetry, TheRollLeavesTheEnergyOnTheAxisAndItsGeneratorIsAKernelVector) {
  const Scene scene = testing::SceneFile("thread3d_axis_cross.yaml");
  const auto model = MakeModel(scene.params);
  const SymmetryCapability* roll = model->symmetry();
  ASSERT_NE(roll, nullptr);
  ASSERT_EQ(roll->NumSymmetries(), 1);
  Vec u(3);
  u << 7.0, 0.0, 0.0;
  // An equilibrium on the axis (the buckled thread), then rolled.
  Scene on_axis = scene;
  auto tracker = MakeTracker(on_axis);
  tracker->Reset(u);
  const Vec x = tracker->state();
  Vec y, g, gy;
  for (double t : {0.3, 1.0, 3.0}) {
    roll->ApplySymmetry(0, t, x, u, &y);
    EXPECT_NEAR(model->Energy(y, u), model->Energy(x, u), 1e-12) << "t = " << t;
    EXPECT_GT((y - x).norm(), 0.1) << "the roll moves the buckled thread";
  }
  // The generator is the roll's derivative, and E_xx g = 0 at the equilibrium.
  roll->SymmetryGenerator(0, x, u, &g);
  const double h = 1e-6;
  Vec yp, ym;
  roll->ApplySymmetry(0, h, x, u, &yp);
  roll->ApplySymmetry(0, -h, x, u, &ym);
  EXPECT_LT(((yp - ym) / (2 * h) - g).norm(), 1e-8 * g.norm());
  SparseMatrix hess = model->HessianPattern();
  model->Hessian(x, u, &hess);
  EXPECT_LT((hess * g).norm(), 1e-6 * g.norm());
  // Off the axis the roll costs energy.
  u[1] = 0.3;
  roll->ApplySymmetry(0, 3.0, x, u, &y);
  EXPECT_GT(std::abs(model->Energy(y, u) - model->Energy(x, u)), 1e-4);
}

TEST(Symmetry, AxisCrossingConvergesEveryRowBothWays) {
  for (const std::string method : {"higher-order", "newton-ls"}) {
    SCOPED_TRACE(method);
    const auto rows = AxisSweep(method);
    ASSERT_EQ(rows.size(), 401u);
    int snaps = 0, max_iterations = 0;
    for (const SweepRow& r : rows) {
      EXPECT_EQ(r.termination, Termination::kConverged) << "row " << r.step;
      EXPECT_LE(r.residual, 1e-6) << "row " << r.step;
      EXPECT_LE(r.iterations, 50) << "row " << r.step;
      max_iterations = std::max(max_iterations, r.iterations);
      snaps += r.snapped ? 1 : 0;
    }
    // The buckle rolls to the other side once each way, just past the axis.
    EXPECT_EQ(snaps, 2);
    EXPECT_TRUE(rows[101].snapped);
    EXPECT_TRUE(rows[301].snapped);
    // F_y turns with the roll: the thread pulls the grasp towards the side of its buckle.
    EXPECT_LT(rows[99].force[1] * rows[102].force[1], 0.0);
    RecordProperty(method + "_max_iterations", max_iterations);
  }
}

TEST(Symmetry, ForceAndStiffnessAgreeWithAndWithoutTheSymmetry) {
  // With an unlimited budget both converge to the same equilibria, so the same F and K,
  // where both converge (without the symmetry the snap minimiser crawls round the orbit
  // for hundreds of iterations and may give up). The tight cutoff pins the state along
  // the soft roll.
  Scene scene = testing::SceneFile("thread3d_axis_cross.yaml");
  scene.solver.cutoff = 1e-10;
  scene.solver.max_iterations = 0;
  auto with = MakeTracker(scene);
  EquilibriumTracker without(std::make_unique<WithoutSymmetries>(MakeModel(scene.params)), scene.solver);
  without.SetSnapThreshold(0.1 * SnapLengthScale(scene.params));
  const auto controls = PathControls(scene, 200);
  int compared_k = 0, unconverged_without = 0;
  for (size_t i = 0; i < controls.size(); ++i) {
    SCOPED_TRACE("row " + std::to_string(i));
    const TrackResult& a = i == 0 ? with->Reset(controls[i]) : with->Update(controls[i]);
    const TrackResult& b = i == 0 ? without.Reset(controls[i]) : without.Update(controls[i]);
    ASSERT_EQ(a.summary.termination, Termination::kConverged);
    if (b.summary.termination != Termination::kConverged) {
      // Without the symmetry the snap minimiser may give up on its crawl round the orbit:
      // no equilibrium to compare with (it catches up at the next row).
      ++unconverged_without;
      continue;
    }
    EXPECT_EQ(a.snapped, b.snapped);
    EXPECT_LT((with->state() - without.state()).lpNorm<Eigen::Infinity>(), 1e-4);
    EXPECT_LT((a.force - b.force).norm(), 1e-6);
    // K where it is defined: E_xx regular (on the axis K is floored, identically).
    if (a.summary.status == EquilibriumStatus::kRegular && b.summary.status == EquilibriumStatus::kRegular) {
      EXPECT_LT((a.stiffness - b.stiffness).norm(), 1e-4 * (1.0 + b.stiffness.norm()));
      ++compared_k;
    }
  }
  EXPECT_LE(unconverged_without, 2);
  EXPECT_GT(compared_k, 390);
}

}  // namespace
}  // namespace snapthread
