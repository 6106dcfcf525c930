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

#include "band_check.h"
#include "models/rod_model.h"
#include "rod_fixtures.h"

namespace snapthread {
namespace {

using V3 = Eigen::Vector3d;

using test_support::RandomBentPair;
using test_support::RandomBentState;
using RandomState = test_support::RodState;
using RandomPair = test_support::RodStatePair;

// E_xx straight into the banded factorisation's storage (model.h): every lower-triangle
// entry of the pattern at its band slot (over NaN-filled storage, so each is written) with
// Hessian()'s value, zeros elsewhere, E and E_x of Energy() and Gradient() to the last bit;
// another bandwidth, or self-contact (its pairs go through the compressed matrix), is
// declined without writing.
TEST(RodModel, BandAssemblyHoldsHessiansValues) {
  std::mt19937 rng(17);
  for (bool free_start : {false, true}) {
    RodParams p = test_support::BentRodParams(9);
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
    const test_support::SeparateValues separate = test_support::EvaluateSeparately(model, x, u);
    const SparseMatrix& h = separate.h;
    const int b = model.HessianBandwidth();
    const int n = model.NumStates();
    const test_support::BandAssembly fused = test_support::AssembleBand(model, x, u, b);
    ASSERT_TRUE(fused.written);
    test_support::ExpectBandHoldsSeparateValues(fused, b, separate, free_start ? "without a clamp" : "clamped");
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
    const test_support::BandAssembly wider = test_support::AssembleBand(model, x, u, b + 1);
    EXPECT_FALSE(wider.written);
    EXPECT_TRUE(wider.Untouched()) << "a declining model wrote the band";
  }
  RodParams pc = test_support::BentRodParams(9);
  pc.contact.enabled = true;
  RodModel contact(pc);
  const RandomState s = RandomBentState(&contact, &rng);
  const test_support::BandAssembly declined = test_support::AssembleBand(contact, s.x, s.u, contact.HessianBandwidth());
  EXPECT_FALSE(declined.written);
  EXPECT_TRUE(declined.Untouched()) << "the model with contact wrote the band";
}

// The grasp maps are kept for the last u (every evaluation of an update asks for the same
// u) and the energy for the last state, but both depend on the lagged frames: after
// AcceptState an evaluation at that same state gives what a model with the same history
// and nothing kept gives, to the last bit.
TEST(RodModel, GraspMapsFollowTheAcceptedFrames) {
  std::mt19937 rng(41);
  const RodParams p = test_support::BentRodParams(8);
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
    const RodParams p = test_support::BentRodParams(10);
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
