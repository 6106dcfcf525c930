// Physics checks of the models beyond their derivatives: consistency between models,
// discrete Euler buckling of the strip, and the cusp point of the Zeeman machine.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "models/models.h"

namespace snapthread {
namespace {

// A chain model of n segments of length l, bending beta and stretching gamma.
ModelParams ChainParams(const std::string& model, int n, double l, double beta, double gamma) {
  ModelParams p;
  p.model = model;
  p.Set("n", n);
  p.Set("segment_length", l);
  p.Set("bending", beta);
  p.Set("stretching", gamma);
  return p;
}

ModelParams Curve2dParams(int n, double l, double beta, double gamma) { return ChainParams("curve2d", n, l, beta, gamma); }

ModelParams Thread3dParams(int n, double l, double beta, double gamma) {
  return ChainParams("thread3d", n, l, beta, gamma);
}

// Index of coordinate k of node i (2 <= i <= n-1) in each model's state vector.
int Curve2dIndex(int i, int k) { return 1 + 2 * (i - 2) + k; }
int Thread3dIndex(int i, int k) { return 1 + 3 * (i - 2) + k; }

// (a) A planar thread3d with (β, γ) is curve2d with (β/2, γ/2): E_i = γ/2 (l - L)² +
// β/2 (b_i - B) against γ (|v| - l)² + β (1 - t·t), with B = 0.
TEST(ModelPhysicsTest, PlanarThread3dEqualsCurve2dWithHalvedStiffness) {
  const double beta = 1.7, gamma = 80.0, l = 0.9;
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int n : {2, 3, 5, 10}) {
    const auto curve = MakeModel(Curve2dParams(n, l, beta / 2.0, gamma / 2.0));
    const auto thread = MakeModel(Thread3dParams(n, l, beta, gamma));
    for (int trial = 0; trial < 5; ++trial) {
      Vec u2(2);
      u2 << 0.8 * n * l, 0.3 * n * l * unit(rng);
      Vec x2 = curve->InitialState(u2);
      for (int i = 0; i < x2.size(); ++i) x2[i] += 0.15 * l * unit(rng);
      // The same planar configuration in thread3d's ordering, z = 0.
      Vec u3(3);
      u3 << u2[0], u2[1], 0.0;
      Vec x3 = Vec::Zero(thread->NumStates());
      x3[0] = x2[0];
      for (int i = 2; i <= n - 1; ++i) {
        for (int k = 0; k < 2; ++k) x3[Thread3dIndex(i, k)] = x2[Curve2dIndex(i, k)];
      }
      const double e2 = curve->Energy(x2, u2);
      EXPECT_NEAR(thread->Energy(x3, u3), e2, 1e-12 * std::abs(e2)) << "n=" << n;

      Vec g2, g3;
      curve->Gradient(x2, u2, &g2);
      thread->Gradient(x3, u3, &g3);
      const double tol = 1e-12 * (g2.norm() + 1.0);
      EXPECT_NEAR(g3[0], g2[0], tol);
      for (int i = 2; i <= n - 1; ++i) {
        EXPECT_NEAR(g3[Thread3dIndex(i, 0)], g2[Curve2dIndex(i, 0)], tol);
        EXPECT_NEAR(g3[Thread3dIndex(i, 1)], g2[Curve2dIndex(i, 1)], tol);
        EXPECT_NEAR(g3[Thread3dIndex(i, 2)], 0.0, tol);  // no force out of the plane
      }

      Vec f2, f3;
      curve->ControlGradient(x2, u2, &f2);
      thread->ControlGradient(x3, u3, &f3);
      EXPECT_NEAR(f3[0], f2[0], tol);
      EXPECT_NEAR(f3[1], f2[1], tol);
      EXPECT_NEAR(f3[2], 0.0, tol);

      // The in-plane Hessian blocks agree too.
      SparseMatrix h2, h3;
      curve->Hessian(x2, u2, &h2);
      thread->Hessian(x3, u3, &h3);
      const Mat d2(h2), d3(h3);
      std::vector<int> map2{0}, map3{0};
      for (int i = 2; i <= n - 1; ++i) {
        for (int k = 0; k < 2; ++k) {
          map2.push_back(Curve2dIndex(i, k));
          map3.push_back(Thread3dIndex(i, k));
        }
      }
      double err = 0.0;
      for (size_t a = 0; a < map2.size(); ++a) {
        for (size_t b = 0; b < map2.size(); ++b) {
          err = std::max(err, std::abs(d3(map3[a], map3[b]) - d2(map2[a], map2[b])));
        }
      }
      EXPECT_LE(err, 1e-10 * (d2.norm() + 1.0)) << "n=" << n;
    }
  }
}

// B (3.9) only shifts the energy, by -N β B / 2.
TEST(ModelPhysicsTest, ReferenceBendShiftsEnergyOnly) {
  ModelParams p = Thread3dParams(6, 1.0, 2.0, 50.0);
  const auto plain = MakeModel(p);
  p.Set("reference_bend", 0.25);
  const auto shifted = MakeModel(p);
  Vec u(3);
  u << 4.0, 1.0, -0.5;
  Vec x = plain->InitialState(u);
  x += 0.1 * Vec::LinSpaced(x.size(), -1.0, 1.0).array().sin().matrix();
  EXPECT_NEAR(shifted->Energy(x, u) - plain->Energy(x, u), -6 * 2.0 * 0.25 / 2.0, 1e-12);
  Vec g1, g2;
  plain->Gradient(x, u, &g1);
  shifted->Gradient(x, u, &g2);
  EXPECT_LE((g1 - g2).norm(), 1e-14 * g1.norm());
}

// With the grip direction equal to the last segment's actual direction and s its length,
// the gripped model is the same thread: same energy, same forces on the free nodes.
TEST(ModelPhysicsTest, GripDirectionAlongLastSegmentMatchesFreeThread) {
  for (int n : {3, 4, 8}) {
    ModelParams p = Thread3dParams(n, 0.6, 1.2, 70.0);
    const auto free_thread = MakeModel(p);
    p.Set("grip_direction", true);
    const auto gripped = MakeModel(p);
    Vec u(3);
    u << 0.7 * n * 0.6, 0.5, 0.4;
    Vec x = free_thread->InitialState(u);
    x += 0.08 * Vec::LinSpaced(x.size(), 0.0, 7.0).array().cos().matrix();
    Eigen::Matrix3Xd nodes;
    free_thread->NodePositions(x, u, &nodes);
    const Eigen::Vector3d last = nodes.col(n) - nodes.col(n - 1);
    Vec ug(6);
    ug << u, 2.5 * last;  // any positive scale of d
    Vec xg(gripped->NumStates());
    xg.head(xg.size() - 1) = x.head(xg.size() - 1);  // x_1 and nodes 2..N-2
    xg[xg.size() - 1] = last.norm();
    const double e = free_thread->Energy(x, u);
    EXPECT_NEAR(gripped->Energy(xg, ug), e, 1e-12 * std::abs(e)) << "n=" << n;
    Vec g, gg;
    free_thread->Gradient(x, u, &g);
    gripped->Gradient(xg, ug, &gg);
    const int shared = gripped->NumStates() - 1;
    EXPECT_LE((g.head(shared) - gg.head(shared)).norm(), 1e-12 * (g.norm() + 1.0));
    // dE/ds is the free gradient at node N-1 projected on -d̂.
    const Eigen::Vector3d g_last = g.tail<3>();
    EXPECT_NEAR(gg[shared], -g_last.dot(last.normalized()), 1e-12 * (g.norm() + 1.0));
  }
}

// The straight strip at end position (X, 0): equilibrium, its compressive force P and the
// smallest eigenvalue of E_xx there.
struct StraightStrip {
  double gradient_norm;
  double force;       // P = F_x = -E_X: positive when the strip pushes the grasp out
  double lambda_min;  // of the dense E_xx
};

StraightStrip EvaluateStraight(const Model& m, int n, double big_x) {
  Vec u(2);
  u << big_x, 0.0;
  Vec x = Vec::Zero(m.NumStates());
  x[0] = big_x / n;
  for (int i = 2; i <= n - 1; ++i) x[Curve2dIndex(i, 0)] = big_x * i / n;
  StraightStrip out;
  Vec g, eu;
  m.Gradient(x, u, &g);
  m.ControlGradient(x, u, &eu);
  SparseMatrix h;
  m.Hessian(x, u, &h);
  Eigen::SelfAdjointEigenSolver<Mat> eig(Mat(h), Eigen::EigenvaluesOnly);
  out.gradient_norm = g.norm();
  out.force = -eu[0];
  out.lambda_min = eig.eigenvalues()[0];
  return out;
}

// (b) Discrete Euler buckling: bisect on X for the compression where λ_min(E_xx) of the
// straight strip crosses zero; the force there against the clamped–pinned elastica load
// 20.19 EI / L², EI = β l, L = n l.
double BucklingLoadRelativeError(int n) {
  const double l = 1.0, beta = 1.0, gamma = 100.0;
  const auto m = MakeModel(Curve2dParams(n, l, beta, gamma));
  const double total = n * l;
  const double p_elastica = 20.19 * beta * l / (total * total);
  EXPECT_NEAR(m->ForceScale(), p_elastica, 1e-12 * p_elastica);
  // Bracket: unloaded (stable) and three times the elastica load (buckled), where the
  // segment length is l - P / (2γ).
  double x_hi = total;
  double x_lo = n * (l - 3.0 * p_elastica / (2.0 * gamma));
  const StraightStrip hi = EvaluateStraight(*m, n, x_hi);
  const StraightStrip lo = EvaluateStraight(*m, n, x_lo);
  EXPECT_GT(hi.lambda_min, 0.0) << "unloaded straight strip must be stable, n=" << n;
  EXPECT_LT(lo.lambda_min, 0.0) << "strip at 3x the Euler load must be unstable, n=" << n;
  EXPECT_GT(lo.force, 0.0) << "compression must push the grasp outwards";
  for (int it = 0; it < 80; ++it) {
    const double mid = 0.5 * (x_lo + x_hi);
    const StraightStrip s = EvaluateStraight(*m, n, mid);
    // The straight strip is an equilibrium for every X (by symmetry and even spacing).
    EXPECT_LE(s.gradient_norm, 1e-10 * gamma * l);
    (s.lambda_min > 0.0 ? x_hi : x_lo) = mid;
  }
  const double p_crit = EvaluateStraight(*m, n, 0.5 * (x_lo + x_hi)).force;
  const double rel = std::abs(p_crit - p_elastica) / p_elastica;
  std::printf("n=%d  P_crit=%.6g  elastica=%.6g  relative error=%.4f\n", n, p_crit, p_elastica,
              rel);
  return rel;
}

TEST(ModelPhysicsTest, Curve2dBucklesNearClampedPinnedEulerLoad) {
  const double e10 = BucklingLoadRelativeError(10);
  const double e20 = BucklingLoadRelativeError(20);
  const double e40 = BucklingLoadRelativeError(40);
  EXPECT_LT(e10, 0.10);
  EXPECT_LT(e20, e10);
  EXPECT_LT(e40, e20);
}

// (c) Zeeman machine (2.4) at X = 0: θ = 0 is an equilibrium for every Y, and at θ = 0
// E_θθ = 3 - 2Y²/(Y + 1), which vanishes at the cusp Y0 = (3 + √33)/4.
double ZeemanEtt(const Model& m, double theta, double big_y) {
  Vec x = Vec::Constant(1, theta), u(2);
  u << 0.0, big_y;
  SparseMatrix h;
  m.Hessian(x, u, &h);
  return h.valuePtr()[0];
}

TEST(ModelPhysicsTest, ZeemanCuspAtAnalyticPoint) {
  const auto m = MakeModel({.model = "zeeman"});
  const double y0 = (3.0 + std::sqrt(33.0)) / 4.0;
  Vec g;
  for (double y : {0.5, 1.5, y0, 3.0, 4.0}) {
    Vec u(2);
    u << 0.0, y;
    m->Gradient(Vec::Zero(1), u, &g);
    EXPECT_NEAR(g[0], 0.0, 1e-14) << "θ = 0 is an equilibrium at X = 0 by symmetry";
  }
  EXPECT_NEAR(ZeemanEtt(*m, 0.0, y0), 0.0, 1e-13);
  EXPECT_GT(ZeemanEtt(*m, 0.0, y0 - 1e-4), 0.0);
  EXPECT_LT(ZeemanEtt(*m, 0.0, y0 + 1e-4), 0.0);
  // Y0 is the (only) zero of E_θθ(0) on [1, 4]: find it by bisection.
  double lo = 1.0, hi = 4.0;
  ASSERT_GT(ZeemanEtt(*m, 0.0, lo), 0.0);
  ASSERT_LT(ZeemanEtt(*m, 0.0, hi), 0.0);
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    (ZeemanEtt(*m, 0.0, mid) > 0.0 ? lo : hi) = mid;
  }
  EXPECT_NEAR(0.5 * (lo + hi), y0, 1e-12);
}

// InitialState is the global minimum: θ = 0 below the cusp, a symmetric pair of
// off-axis minima above it.
TEST(ModelPhysicsTest, ZeemanInitialStateIsGlobalMinimum) {
  const auto m = MakeModel({.model = "zeeman"});
  const double y0 = (3.0 + std::sqrt(33.0)) / 4.0;
  Vec u(2), g;
  u << 0.0, y0 - 0.5;
  EXPECT_NEAR(m->InitialState(u)[0], 0.0, 1e-9);
  u << 0.0, y0 + 0.5;
  const Vec x = m->InitialState(u);
  EXPECT_GT(std::abs(x[0]), 0.1);
  m->Gradient(x, u, &g);
  EXPECT_NEAR(g[0], 0.0, 1e-10);
  EXPECT_GT(ZeemanEtt(*m, x[0], u[1]), 0.0);
  EXPECT_LT(m->Energy(x, u), m->Energy(Vec::Zero(1), u));
  EXPECT_NEAR(m->Energy(x, u), m->Energy(-x, u), 1e-12);
  // Off axis: no grid point beats the returned state.
  u << 0.4, 2.6;
  const Vec xs = m->InitialState(u);
  m->Gradient(xs, u, &g);
  EXPECT_NEAR(g[0], 0.0, 1e-10);
  for (int i = 0; i < 3600; ++i) {
    const Vec t = Vec::Constant(1, -std::numbers::pi + 2.0 * std::numbers::pi * i / 3600.0);
    EXPECT_LE(m->Energy(xs, u), m->Energy(t, u) + 1e-12);
  }
}

}  // namespace
}  // namespace snapthread
