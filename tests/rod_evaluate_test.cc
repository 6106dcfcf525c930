// The rod's evaluation machinery (common/models/rod_evaluate.cc): E_xx written straight
// into band storage, and what the model keeps between calls (grasp maps, the last energy,
// the last band) dropped when the lagged frames move.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "models/rod_model.h"

namespace snapthread {
namespace {

using V3 = Eigen::Vector3d;

// A ribbon-like rod with natural curvature, clamp and grasp turned (as rod_test.cc's).
RodParams BentParams(int n) {
  RodParams p;
  p.n = n;
  p.length = 1.3;
  p.stretch_stiffness = 50.0;
  p.bend_stiffness = 1.0;
  p.bend_stiffness_2 = 2.7;
  p.twist_stiffness = 0.8;
  p.natural_curvature = 0.9;
  p.natural_curvature_2 = -0.4;
  p.clamp_position = V3(0.1, -0.2, 0.3);
  p.clamp_rotation = Eigen::AngleAxisd(0.4, V3(1, 2, 3).normalized()).toRotationMatrix();
  p.grasp_rotation = Eigen::AngleAxisd(-0.3, V3(0, 1, 1).normalized()).toRotationMatrix() * p.clamp_rotation;
  return p;
}

struct RandomState {
  Vec x, u;
};

// The grasp moved and rolled, nodes and angles perturbed from the initial state.
RandomState Perturbed(const RodModel& model, const Vec& x0, const Vec& u0, std::mt19937* rng) {
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  RandomState s{x0, u0};
  const double l = model.params().length / model.params().n;
  for (int i = 0; i < s.x.size(); ++i) s.x[i] += 0.2 * l * d(*rng);
  for (int j = 1; j <= model.params().n - 2; ++j) s.x[model.ThetaIndex(j)] += 0.6 * d(*rng);
  for (int c = 0; c < 3; ++c) s.u[c] += 0.2 * l * d(*rng);
  for (int c = 3; c < 6; ++c) s.u[c] += 0.2 * d(*rng);
  return s;
}

struct RandomPair {
  RandomState older, newer;
};

RandomPair RandomBentPair(const RodModel& model, std::mt19937* rng) {
  const RodParams& p = model.params();
  Vec u(6);
  u << p.clamp_position + 0.8 * p.length * p.clamp_rotation.col(0) + V3(0.05, 0.2, -0.1) * p.length, 0.3, -0.5,
      1.2;
  RandomPair pair;
  pair.older = Perturbed(model, model.InitialState(u), u, rng);
  pair.newer = Perturbed(model, pair.older.x, pair.older.u, rng);
  return pair;
}

// The frames accepted at one random state, evaluated at another (twist rates non-zero).
RandomState RandomBentState(RodModel* model, std::mt19937* rng) {
  const RandomPair pair = RandomBentPair(*model, rng);
  model->AcceptState(pair.older.x, pair.older.u);
  return pair.newer;
}

// E_xx straight into the banded factorisation's storage (model.h): every lower-triangle
// entry of the pattern at its band slot (over NaN-filled storage, so each is written) with
// Hessian()'s value, zeros elsewhere, E and E_x of Energy() and Gradient() to the last bit;
// another bandwidth, or self-contact (its pairs go through the compressed matrix), is
// declined without writing.
TEST(RodModel, BandAssemblyHoldsHessiansValues) {
  std::mt19937 rng(17);
  for (bool free_start : {false, true}) {
    RodParams p = BentParams(9);
    p.free_start = free_start;
    RodModel model(p);
    Vec x, u;
    if (!free_start) {
      const RandomState s = RandomBentState(&model, &rng);
      x = s.x;
      u = s.u;
    } else {  // two grasps: the first near the clamp's pose, the second further on, turned
      u.resize(12);
      u << p.clamp_position, 0.1, -0.2, 0.05, p.clamp_position + 0.7 * p.length * p.clamp_rotation.col(0),
          0.3, -0.5, 1.2;
      std::uniform_real_distribution<double> d(-1.0, 1.0);
      x = model.InitialState(u);
      for (int i = 0; i < x.size(); ++i) x[i] += 0.03 * d(rng);
    }
    SparseMatrix h = model.HessianPattern();
    Vec g;
    model.Hessian(x, u, &h);
    model.Gradient(x, u, &g);
    const double e = model.Energy(x, u);
    const int b = model.HessianBandwidth();
    const int n = model.NumStates();
    std::vector<double> band(static_cast<size_t>(n) * (b + 1), std::numeric_limits<double>::quiet_NaN());
    Vec g4;
    double e4 = 0.0;
    ASSERT_TRUE(model.EnergyGradientAndBandHessian(x, u, &g4, band.data(), b, &e4));
    EXPECT_EQ(std::memcmp(&e, &e4, sizeof e), 0) << e << " vs " << e4;
    ASSERT_EQ(g4.size(), g.size());
    EXPECT_EQ(std::memcmp(g.data(), g4.data(), sizeof(double) * g.size()), 0);
    std::vector<char> in_pattern(band.size(), 0);
    for (int j = 0; j < n; ++j) {
      for (SparseMatrix::InnerIterator it(h, j); it; ++it) {
        if (it.row() < j) continue;
        const size_t slot = static_cast<size_t>(it.row()) * (b + 1) + j - it.row() + b;
        in_pattern[slot] = 1;
        EXPECT_EQ(band[slot], it.value()) << "E_xx(" << it.row() << ", " << j << ")";
      }
    }
    for (size_t k = 0; k < band.size(); ++k) {
      if (!in_pattern[k]) {
        EXPECT_EQ(band[k], 0.0) << "slot " << k << " outside the pattern";
      }
    }
    // The compressed matrix asked for at the band's state (a solver that factorised the
    // band in place does): the same values.
    SparseMatrix h2 = model.HessianPattern();
    model.Hessian(x, u, &h2);
    for (int j = 0; j < n; ++j) {
      for (int k = h.outerIndexPtr()[j]; k < h.outerIndexPtr()[j + 1]; ++k) {
        EXPECT_EQ(h2.valuePtr()[k], h.valuePtr()[k]) << "E_xx(" << h.innerIndexPtr()[k] << ", " << j << ")"
                                                     << (free_start ? " without a clamp" : "");
      }
    }
    std::fill(band.begin(), band.end(), std::numeric_limits<double>::quiet_NaN());
    band.resize(static_cast<size_t>(n) * (b + 2), std::numeric_limits<double>::quiet_NaN());
    EXPECT_FALSE(model.EnergyGradientAndBandHessian(x, u, &g4, band.data(), b + 1, &e4));
    for (double v : band) EXPECT_TRUE(std::isnan(v)) << "a declining model wrote the band";
  }
  RodParams pc = BentParams(9);
  pc.contact.enabled = true;
  RodModel contact(pc);
  const RandomState s = RandomBentState(&contact, &rng);
  const int b = contact.HessianBandwidth();
  std::vector<double> band(static_cast<size_t>(contact.NumStates()) * (b + 1), std::numeric_limits<double>::quiet_NaN());
  Vec g;
  double e = 0.0;
  EXPECT_FALSE(contact.EnergyGradientAndBandHessian(s.x, s.u, &g, band.data(), b, &e));
  for (double v : band) EXPECT_TRUE(std::isnan(v)) << "the model with contact wrote the band";
}

// The grasp maps are kept for the last u (every evaluation of an update asks for the same
// u) and the energy for the last state, but both depend on the lagged frames: after
// AcceptState an evaluation at that same state gives what a model with the same history
// and nothing kept gives, to the last bit.
TEST(RodModel, GraspMapsFollowTheAcceptedFrames) {
  std::mt19937 rng(41);
  const RodParams p = BentParams(8);
  RodModel kept(p), fresh(p);
  const RandomPair pair = RandomBentPair(kept, &rng);
  const RandomState& s = pair.newer;
  Vec g0, eu0;
  kept.Gradient(s.x, s.u, &g0);  // fills the cache at s.u against the rest frames
  kept.ControlGradient(s.x, s.u, &eu0);
  const double e0 = kept.Energy(s.x, s.u);
  kept.AcceptState(pair.older.x, pair.older.u);
  fresh.AcceptState(pair.older.x, pair.older.u);
  const double e1 = kept.Energy(s.x, s.u), e2 = fresh.Energy(s.x, s.u);
  EXPECT_NE(e1, e0);
  EXPECT_EQ(std::memcmp(&e1, &e2, sizeof e1), 0) << e1 << " vs " << e2;
  Vec g1, g2, eu1, eu2;
  kept.Gradient(s.x, s.u, &g1);
  fresh.Gradient(s.x, s.u, &g2);
  kept.ControlGradient(s.x, s.u, &eu1);
  fresh.ControlGradient(s.x, s.u, &eu2);
  EXPECT_GT((g1 - g0).norm(), 0.0);  // the frames moved: the values did change
  EXPECT_EQ(std::memcmp(g1.data(), g2.data(), sizeof(double) * g1.size()), 0);
  EXPECT_EQ(std::memcmp(eu1.data(), eu2.data(), sizeof(double) * eu1.size()), 0);
  kept.ResetHistory();
  RodModel rest(p);
  kept.Gradient(s.x, s.u, &g1);
  rest.Gradient(s.x, s.u, &g2);
  EXPECT_EQ(std::memcmp(g1.data(), g2.data(), sizeof(double) * g1.size()), 0);
}


// A gradient pass keeps its energy, and AcceptState at the state of the last pass over
// every term takes that pass's frames and reference twists instead of computing them:
// both give, to the last bit, what a model that computes everything afresh gives.
TEST(RodModel, KeptPassValuesAreTheComputedOnes) {
  std::mt19937 rng(23);
  for (const char* what : {"gradient", "band", "energy"}) {
    const RodParams p = BentParams(10);
    RodModel kept(p), fresh(p);
    const RandomPair pair = RandomBentPair(kept, &rng);
    Vec g;
    if (std::string(what) == "gradient") {
      kept.Gradient(pair.older.x, pair.older.u, &g);
      const double e_kept = kept.Energy(pair.older.x, pair.older.u);
      const double e_fresh = fresh.Energy(pair.older.x, pair.older.u);
      EXPECT_EQ(std::memcmp(&e_kept, &e_fresh, sizeof e_kept), 0) << e_kept << " vs " << e_fresh;
    } else if (std::string(what) == "band") {
      const int b = kept.HessianBandwidth();
      std::vector<double> band(static_cast<size_t>(kept.NumStates()) * (b + 1));
      double e = 0.0;
      ASSERT_TRUE(kept.EnergyGradientAndBandHessian(pair.older.x, pair.older.u, &g, band.data(), b, &e));
    } else {
      kept.Energy(pair.older.x, pair.older.u);
    }
    kept.AcceptState(pair.older.x, pair.older.u);
    fresh.AcceptState(pair.older.x, pair.older.u);
    const double e1 = kept.Energy(pair.newer.x, pair.newer.u), e2 = fresh.Energy(pair.newer.x, pair.newer.u);
    EXPECT_EQ(std::memcmp(&e1, &e2, sizeof e1), 0) << what << ": " << e1 << " vs " << e2;
    Vec g1, g2;
    kept.Gradient(pair.newer.x, pair.newer.u, &g1);
    fresh.Gradient(pair.newer.x, pair.newer.u, &g2);
    EXPECT_EQ(std::memcmp(g1.data(), g2.data(), sizeof(double) * g1.size()), 0) << what;
    const Vec twist1 = kept.TwistDensity(pair.newer.x, pair.newer.u), twist2 = fresh.TwistDensity(pair.newer.x, pair.newer.u);
    EXPECT_EQ(std::memcmp(twist1.data(), twist2.data(), sizeof(double) * twist1.size()), 0) << what;
  }
}

}  // namespace
}  // namespace snapthread
