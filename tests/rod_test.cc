// The discrete elastic rod (common/models/rod_model.h): exact derivatives against
// central differences and forward-mode autodiff, the allocation-free Hessian refill,
// rigid-motion invariance, the lagged frames, and Greenhill's twist buckling with the
// EquilibriumTracker.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <random>

#include "models/rod_model.h"

namespace snapthread {
namespace {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

RodParams BentParams(int n) {
  RodParams p;
  p.n = n;
  p.length = 1.3;
  p.stretch_stiffness = 50.0;
  p.bend_stiffness = 1.0;
  p.bend_stiffness_2 = 2.7;  // unequal: a ribbon-like cross-section
  p.twist_stiffness = 0.8;
  p.natural_curvature = 0.9;
  p.natural_curvature_2 = -0.4;
  p.clamp_position = V3(0.1, -0.2, 0.3);
  p.clamp_rotation = Eigen::AngleAxisd(0.4, V3(1, 2, 3).normalized()).toRotationMatrix();
  p.grasp_rotation = Eigen::AngleAxisd(-0.3, V3(0, 1, 1).normalized()).toRotationMatrix() *
                     p.clamp_rotation;
  return p;
}

// A random bent and twisted state: the grasp moved and rolled, nodes and angles
// perturbed, and the lagged frames accepted at another random state first (so the
// twist-rate terms of the reference frames are not zero where the derivatives are checked).
struct RandomState {
  Vec x, u;
};

RandomState Perturbed(const RodModel& model, const Vec& x0, const Vec& u0, double amount,
                      std::mt19937* rng) {
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  RandomState s{x0, u0};
  const double l = model.params().length / model.params().n;
  for (int i = 0; i < s.x.size(); ++i) s.x[i] += amount * l * d(*rng);
  for (int j = 1; j <= model.params().n - 2; ++j) s.x[model.ThetaIndex(j)] += amount * 3.0 * d(*rng);
  for (int c = 0; c < 3; ++c) s.u[c] += amount * l * d(*rng);
  for (int c = 3; c < 6; ++c) s.u[c] += amount * d(*rng);
  return s;
}

RandomState RandomBentState(RodModel* model, std::mt19937* rng) {
  const double len = model->params().length;
  Vec u(6);
  u << model->params().clamp_position + 0.8 * len * model->params().clamp_rotation.col(0) +
           V3(0.05, 0.2, -0.1) * len,
      0.3, -0.5, 1.2;
  const Vec x0 = model->InitialState(u);
  const RandomState older = Perturbed(*model, x0, u, 0.2, rng);
  model->AcceptState(older.x, older.u);
  return Perturbed(*model, older.x, older.u, 0.2, rng);
}

Mat DenseHessian(const Model& m, const Vec& x, const Vec& u) {
  SparseMatrix h = m.HessianPattern();
  m.Hessian(x, u, &h);
  return Mat(h);
}

double RelErr(const Mat& a, const Mat& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

class RodDerivatives : public ::testing::TestWithParam<int> {};

TEST_P(RodDerivatives, MatchCentralDifferences) {
  const int n = GetParam();
  std::mt19937 rng(1234 + n);
  for (int trial = 0; trial < 3; ++trial) {
    RodModel model(BentParams(n));
    const RandomState s = RandomBentState(&model, &rng);
    const Vec& x = s.x;
    const Vec& u = s.u;
    const int nx = model.NumStates();
    ASSERT_EQ(nx, 4 * n - 11);
    const double h = 1e-6;
    Vec g, eu;
    model.Gradient(x, u, &g);
    model.ControlGradient(x, u, &eu);
    Mat hxx = DenseHessian(model, x, u);
    Mat exu, euu;
    model.MixedHessian(x, u, &exu);
    model.ControlHessian(x, u, &euu);
    Vec fd_g(nx), fd_eu(6);
    Mat fd_h(nx, nx), fd_exu(nx, 6), fd_euu(6, 6);
    for (int i = 0; i < nx; ++i) {
      Vec xp = x, xm = x;
      xp[i] += h;
      xm[i] -= h;
      fd_g[i] = (model.Energy(xp, u) - model.Energy(xm, u)) / (2 * h);
      Vec gp, gm;
      model.Gradient(xp, u, &gp);
      model.Gradient(xm, u, &gm);
      fd_h.col(i) = (gp - gm) / (2 * h);
    }
    for (int c = 0; c < 6; ++c) {
      Vec up = u, um = u;
      up[c] += h;
      um[c] -= h;
      fd_eu[c] = (model.Energy(x, up) - model.Energy(x, um)) / (2 * h);
      Vec gp, gm, ep, em;
      model.Gradient(x, up, &gp);
      model.Gradient(x, um, &gm);
      fd_exu.col(c) = (gp - gm) / (2 * h);
      model.ControlGradient(x, up, &ep);
      model.ControlGradient(x, um, &em);
      fd_euu.col(c) = (ep - em) / (2 * h);
    }
    EXPECT_LT(RelErr(g, fd_g), 1e-6) << "E_x n=" << n;
    EXPECT_LT(RelErr(hxx, fd_h), 1e-6) << "E_xx n=" << n;
    EXPECT_LT(RelErr(hxx, hxx.transpose()), 1e-12) << "E_xx symmetric n=" << n;
    EXPECT_LT(RelErr(eu, fd_eu), 1e-6) << "E_u n=" << n;
    EXPECT_LT(RelErr(exu, fd_exu), 1e-6) << "E_xu n=" << n;
    EXPECT_LT(RelErr(euu, fd_euu), 1e-6) << "E_uu n=" << n;
    EXPECT_LT(RelErr(euu, euu.transpose()), 1e-10) << "E_uu symmetric n=" << n;
    std::printf("n=%d errs g %.2e h %.2e eu %.2e exu %.2e euu %.2e |g| %.2e |h| %.2e |exu| %.2e\n", n, RelErr(g, fd_g), RelErr(hxx, fd_h), RelErr(eu, fd_eu), RelErr(exu, fd_exu), RelErr(euu, fd_euu), g.norm(), hxx.norm(), exu.norm());
    // The state is really bent and twisted.
    EXPECT_GT(g.norm(), 1e-2);
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, RodDerivatives, ::testing::Values(3, 5, 12));

}  // namespace
}  // namespace snapthread
