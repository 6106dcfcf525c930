// Snaps happen where the analytic fold set says (zeeman: E_theta = E_thetatheta = 0;
// cusp: 27 X^2 = -4 Y^3), to within the step size.
#include <cmath>

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "models/models.h"
#include "sweep.h"

namespace snapthread {
namespace {

// Fold X of the Zeeman machine at height Y near X0: Newton on (E_theta, E_thetatheta)
// = 0 in (theta, X), derivatives by the model's analytic gradient/Hessian and central
// differences in X and theta of those.
double ZeemanFoldX(double y, double x0, double theta0) {
  auto model = MakeModel({.model = "zeeman"});
  Vec th(1), u(2), g;
  SparseMatrix h = model->HessianPattern();
  auto f = [&](double t, double x, double* e1, double* e2) {
    th[0] = t;
    u << x, y;
    model->Gradient(th, u, &g);
    model->Hessian(th, u, &h);
    *e1 = g[0];
    *e2 = h.valuePtr()[0];
  };
  double t = theta0, x = x0;
  for (int it = 0; it < 60; ++it) {
    double a, b;
    f(t, x, &a, &b);
    const double d = 1e-6;
    double at, bt, ax, bx;
    f(t + d, x, &at, &bt);
    double am, bm;
    f(t - d, x, &am, &bm);
    const double a_t = (at - am) / (2 * d), b_t = (bt - bm) / (2 * d);
    f(t, x + d, &ax, &bx);
    f(t, x - d, &am, &bm);
    const double a_x = (ax - am) / (2 * d), b_x = (bx - bm) / (2 * d);
    const double det = a_t * b_x - a_x * b_t;
    const double dt = (a * b_x - b * a_x) / det, dx = (a_t * b - b_t * a) / det;
    t -= dt;
    x -= dx;
    if (std::abs(dt) + std::abs(dx) < 1e-13) break;
  }
  return x;
}

// Index of the first snap in rows [from, to), or 0 if none.
size_t FirstSnap(const std::vector<SweepRow>& rows, size_t from, size_t to) {
  for (size_t i = from; i < to && i < rows.size(); ++i)
    if (rows[i].snapped) return i;
  return 0;
}
double FirstSnapX(const std::vector<SweepRow>& rows, size_t from, size_t to) {
  const size_t i = FirstSnap(rows, from, to);
  return i ? rows[i].u[0] : std::nan("");
}

class FoldPlacement : public ::testing::TestWithParam<std::string> {};

TEST_P(FoldPlacement, ZeemanJumpsAtTheAnalyticFolds) {
  const double y = 3.0;
  Scene scene;
  scene.params.model = "zeeman";
  scene.grasp_start = Vec(2);
  scene.grasp_start << -1.0, y;
  scene.solver.method = GetParam();
  scene.solver.max_iterations = 0;  // the placement of the jump, not the budget
  const int n = 500;
  SweepSpec spec{scene.grasp_start, Vec(2), n, true};
  spec.to << 1.0, y;
  auto tracker = MakeTracker(scene);
  const auto rows = RunSweep(tracker.get(), SweepControls(scene, spec));
  const double step = 2.0 / n;
  // Going right the wheel leaves its branch at the right fold, going left at the left.
  // The analytic fold is solved from the last tracked state before each jump.
  const size_t i_up = FirstSnap(rows, 1, n + 1), i_down = FirstSnap(rows, n + 1, rows.size());
  ASSERT_GT(i_up, 0u);
  ASSERT_GT(i_down, 0u);
  const double fold_right = ZeemanFoldX(y, rows[i_up - 1].u[0], rows[i_up - 1].probe);
  const double fold_left = ZeemanFoldX(y, rows[i_down - 1].u[0], rows[i_down - 1].probe);
  ASSERT_TRUE(std::isfinite(fold_right) && std::isfinite(fold_left));
  EXPECT_GT(fold_right, 0.3);
  EXPECT_LT(fold_left, -0.3);
  const double up = FirstSnapX(rows, 1, n + 1);
  const double down = FirstSnapX(rows, n + 1, rows.size());
  EXPECT_GE(up, fold_right - 1e-9);
  EXPECT_LE(up, fold_right + step + 1e-9);
  EXPECT_LE(down, fold_left + 1e-9);
  EXPECT_GE(down, fold_left - step - 1e-9);
}

TEST_P(FoldPlacement, CuspJumpsOn27X2EqualsMinus4Y3) {
  const double y = -1.0;
  Scene scene;
  scene.params.model = "cusp";
  scene.grasp_start = Vec(2);
  scene.grasp_start << -1.0, y;
  scene.solver.method = GetParam();
  scene.solver.max_iterations = 0;
  const int n = 400;
  SweepSpec spec{scene.grasp_start, Vec(2), n, true};
  spec.to << 1.0, y;
  auto tracker = MakeTracker(scene);
  const auto rows = RunSweep(tracker.get(), SweepControls(scene, spec));
  const double fold = std::sqrt(-4.0 * y * y * y / 27.0);
  const double step = 2.0 / n;
  const double up = FirstSnapX(rows, 1, n + 1);
  const double down = FirstSnapX(rows, n + 1, rows.size());
  EXPECT_GE(up, fold - 1e-9);
  EXPECT_LE(up, fold + step + 1e-9);
  EXPECT_LE(down, -fold + 1e-9);
  EXPECT_GE(down, -fold - step - 1e-9);
  // Between jumps the state follows the analytic branch T^3 + Y T + X = 0.
  for (const auto& r : rows) {
    const double t = r.probe;
    EXPECT_NEAR(t * t * t + y * t + r.u[0], 0.0, 1e-5);
  }
}

// The fold of curve2d_snap solved independently of any sweep, as a continuation code
// would: the Moore-Spence system E_x(x, Y) = 0, E_xx(x, Y) v = 0, v_k = 1 in the
// unknowns (x, v, Y), by Newton with a finite-difference Jacobian, started from the last
// state before the snap.
double Curve2dFoldY(const Model& model, double x_grasp, Vec x, Vec v, double y) {
  const int n = model.NumStates();
  int k = 0;
  v.cwiseAbs().maxCoeff(&k);
  v /= v[k];
  SparseMatrix h = model.HessianPattern();
  auto residual = [&](const Vec& z) {
    Vec u(2), g;
    u << x_grasp, z[2 * n];
    const Vec xs = z.head(n), vs = z.segment(n, n);
    model.Gradient(xs, u, &g);
    model.Hessian(xs, u, &h);
    Vec r(2 * n + 1);
    r.head(n) = g;
    r.segment(n, n) = h * vs;
    r[2 * n] = vs[k] - 1.0;
    return r;
  };
  Vec z(2 * n + 1);
  z << x, v, y;
  for (int it = 0; it < 30; ++it) {
    const Vec r = residual(z);
    if (r.norm() < 1e-11) break;
    Mat jac(2 * n + 1, 2 * n + 1);
    for (int j = 0; j < 2 * n + 1; ++j) {
      const double d = 1e-7 * std::max(1.0, std::abs(z[j]));
      Vec zp = z, zm = z;
      zp[j] += d;
      zm[j] -= d;
      jac.col(j) = (residual(zp) - residual(zm)) / (2 * d);
    }
    z -= jac.fullPivLu().solve(r);
  }
  EXPECT_LT(residual(z).norm(), 1e-8);
  return z[2 * n];
}

TEST(FoldPlacement, Curve2dSnapsOnTheFirstStepPastTheMooreSpenceFold) {
  const Scene scene = LoadScene(std::string(SNAPTHREAD_TEST_SOURCE_DIR) + "/scenes/curve2d_snap.yaml");
  for (int budget : {2, 3, 0}) {
    Scene sc = scene;
    sc.solver.method = "higher-order";
    sc.solver.max_iterations = budget;
    auto tracker = MakeTracker(sc);
    const double step = 0.002;
    Vec u(2);
    u << 9.0, 3.0;
    tracker->Reset(u);
    Vec x_before, v_before;
    double y_before = 0.0, y_snap = 0.0;
    for (int i = 1; i <= 400 && y_snap == 0.0; ++i) {
      x_before = tracker->state();
      y_before = u[1];
      u[1] = 3.0 + step * i;
      const TrackResult& r = tracker->Update(u);
      if (r.snapped) y_snap = u[1];
    }
    ASSERT_GT(y_snap, 0.0) << "no snap between Y = 3.0 and 3.8";
    // The lowest mode at the last state before the snap seeds the fold solve.
    auto model = MakeModel(sc.params);
    SparseMatrix h = model->HessianPattern();
    Vec ub(2);
    ub << 9.0, y_before;
    model->Hessian(x_before, ub, &h);
    Eigen::SelfAdjointEigenSolver<Mat> eig{Mat(h)};
    const double fold = Curve2dFoldY(*model, 9.0, x_before, eig.eigenvectors().col(0), y_before);
    EXPECT_GT(fold, y_snap - step - 1e-9) << "budget " << budget;
    EXPECT_LE(fold, y_snap + 1e-9) << "budget " << budget;
  }
}

INSTANTIATE_TEST_SUITE_P(Methods, FoldPlacement,
                         ::testing::Values("newton-ls", "higher-order"),
                         [](const auto& info) {
                           std::string s = info.param;
                           for (char& c : s)
                             if (c == '-') c = '_';
                           return s;
                         });

}  // namespace
}  // namespace snapthread
