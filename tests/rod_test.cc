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
#include <string>
#include <vector>

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "allocation_counter.h"
#include "finite_difference.h"
#include "models/rod_energy.h"
#include "models/rod_model.h"
#include "rod_fixtures.h"
#include "solvers/registry.h"
#include "tracking/tracker.h"

namespace snapthread {
namespace {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

using test_support::BentRodParams;
using test_support::MaxRelativeError;
using test_support::RandomBentPair;
using test_support::RandomBentState;
using RandomState = test_support::RodState;
using RandomPair = test_support::RodStatePair;

class RodDerivatives : public ::testing::TestWithParam<int> {};

TEST_P(RodDerivatives, MatchCentralDifferences) {
  const int n = GetParam();
  std::mt19937 rng(1234 + n);
  for (int trial = 0; trial < 3; ++trial) {
    RodModel model(BentRodParams(n));
    const RandomState s = RandomBentState(&model, &rng);
    const Vec& x = s.x;
    const Vec& u = s.u;
    const int nx = model.NumStates();
    ASSERT_EQ(nx, 4 * n - 11);
    const test_support::ModelDerivatives exact = test_support::ReportedDerivatives(model, x, u);
    const test_support::ModelDerivatives fd = test_support::CentralDifferences(model, x, u, 1e-6);
    EXPECT_LT(MaxRelativeError(exact.e_x, fd.e_x), 1e-6) << "E_x n=" << n;
    EXPECT_LT(MaxRelativeError(exact.e_xx, fd.e_xx), 1e-6) << "E_xx n=" << n;
    EXPECT_LT(MaxRelativeError(exact.e_xx, exact.e_xx.transpose()), 1e-12) << "E_xx symmetric n=" << n;
    EXPECT_LT(MaxRelativeError(exact.e_u, fd.e_u), 1e-6) << "E_u n=" << n;
    EXPECT_LT(MaxRelativeError(exact.e_xu, fd.e_xu), 1e-6) << "E_xu n=" << n;
    EXPECT_LT(MaxRelativeError(exact.e_uu, fd.e_uu), 1e-6) << "E_uu n=" << n;
    EXPECT_LT(MaxRelativeError(exact.e_uu, exact.e_uu.transpose()), 1e-10) << "E_uu symmetric n=" << n;
    // The state is really bent and twisted.
    EXPECT_GT(exact.e_x.norm(), 1e-2);
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, RodDerivatives, ::testing::Values(3, 5, 12));



// The vertex energy written once more from its definition, with transported frames
// and the reference twist as an angle (no twist rates, no hand-derived formulas), and
// differentiated by nested forward-mode autodiff.
template <class T>
using V3T = Eigen::Matrix<T, 3, 1>;

template <class T>
V3T<T> TransportT(const V3T<T>& t0, const V3T<T>& t1, const V3T<T>& v) {
  const V3T<T> k = t0.cross(t1);
  const T c = t0.dot(t1);
  return c * v + k.cross(v) + (k.dot(v) / (T(1.0) + c)) * k;
}

template <class T>
T VertexEnergyByDefinition(const Eigen::Matrix<T, 8, 1>& z, const rod::FrameSource* src,
                           const rod::VertexStiffness& k) {
  using std::atan2;
  using std::cos;
  using std::sin;
  using std::sqrt;
  const V3T<T> e[2] = {z.template head<3>(), z.template segment<3>(3)};
  V3T<T> t[2], a[2], m1[2], m2[2];
  for (int j = 0; j < 2; ++j) {
    t[j] = e[j] / sqrt(e[j].dot(e[j]));
    a[j] = TransportT<T>(src[j].t.cast<T>(), t[j], src[j].a.cast<T>());
    const V3T<T> b = t[j].cross(a[j]);
    const T c = cos(z[6 + j]), s = sin(z[6 + j]);
    m1[j] = c * a[j] + s * b;
    m2[j] = -s * a[j] + c * b;
  }
  const T chi = sqrt(e[0].dot(e[0])) * sqrt(e[1].dot(e[1])) + e[0].dot(e[1]);
  const V3T<T> kb = (T(2.0) / chi) * e[0].cross(e[1]);
  T bend(0.0);
  for (int j = 0; j < 2; ++j) {
    const T k1 = m2[j].dot(kb) - T(k.kappa1_bar);
    const T k2 = -m1[j].dot(kb) - T(k.kappa2_bar);
    bend += T(0.25) * (T(k.c1) * k1 * k1 + T(k.c2) * k2 * k2);
  }
  const V3T<T> p = TransportT<T>(t[0], t[1], a[0]);
  const T mref = atan2(p.cross(a[1]).dot(t[1]), p.dot(a[1]));
  const T tau = z[7] - z[6] + mref;
  return bend + T(0.5) * T(k.ct) * tau * tau;
}

TEST(RodVertex, MatchesForwardModeAutodiff) {
  using Inner = Eigen::AutoDiffScalar<Eigen::Matrix<double, 8, 1>>;
  using Outer = Eigen::AutoDiffScalar<Eigen::Matrix<Inner, 8, 1>>;
  rod::FrameSource src[2];
  src[0].t = V3(1.0, 0.3, -0.2).normalized();
  src[0].a = src[0].t.cross(V3(0.2, 1.0, 0.4)).normalized();
  src[1].t = V3(0.8, -0.4, 0.5).normalized();
  src[1].a = src[1].t.cross(V3(-0.3, 0.2, 1.0)).normalized();
  rod::VertexStiffness k;
  k.c1 = 1.3;
  k.c2 = 3.1;
  k.ct = 0.7;
  k.kappa1_bar = 0.2;
  k.kappa2_bar = -0.15;
  // Edges away from the sources: the time-parallel frames have turned (Â ≠ 0).
  rod::Vec8 z;
  z << 0.9, 0.5, -0.1, 0.7, -0.3, 0.6, 0.4, -1.1;
  Eigen::Matrix<Outer, 8, 1> zz;
  for (int i = 0; i < 8; ++i) {
    zz[i] = Outer(Inner(z[i], 8, i), 8, i);
    for (int j = 0; j < 8; ++j) zz[i].derivatives()[j].derivatives().setZero();
  }
  const Outer e = VertexEnergyByDefinition<Outer>(zz, src, k);
  rod::Vec8 g_ad;
  rod::Mat8 h_ad;
  for (int i = 0; i < 8; ++i) {
    g_ad[i] = e.derivatives()[i].value();
    h_ad.row(i) = e.derivatives()[i].derivatives().transpose();
  }
  const double mref = rod::ReferenceTwist(z.head<3>(), z.segment<3>(3), src[0], src[1], 0.0);
  rod::Vec8 g;
  rod::Mat8 h;
  const double energy = rod::VertexEnergy(z.head<3>(), z.segment<3>(3), z[6], z[7], src[0],
                                          src[1], mref, k, &g, &h);
  EXPECT_NEAR(energy, e.value().value(), 1e-13);
  EXPECT_LT((g - g_ad).norm(), 1e-12 * std::max(1.0, g_ad.norm()));
  EXPECT_LT((h - h_ad).cwiseAbs().maxCoeff(), 1e-12 * std::max(1.0, h_ad.cwiseAbs().maxCoeff()));
  // The twist-rate (holonomy) terms matter here: the hand-derived gradient without them
  // would differ.
  EXPECT_GT(rod::TwistRate(src[1].t, z.segment<3>(3).normalized()).norm(), 0.05);
}

TEST(RodModel, HessianRefillDoesNotAllocate) {
  std::mt19937 rng(7);
  RodModel model(BentRodParams(12));
  const RandomState s = RandomBentState(&model, &rng);
  SparseMatrix h = model.HessianPattern();
  Vec g(model.NumStates()), eu(6);
  Mat exu(model.NumStates(), 6), euu(6, 6);
  model.Hessian(s.x, s.u, &h);
  const Mat first(h);
  test_support::AllocationCounter counter;
  model.Hessian(s.x, s.u, &h);
  model.Gradient(s.x, s.u, &g);
  model.ControlGradient(s.x, s.u, &eu);
  model.MixedHessian(s.x, s.u, &exu);
  model.ControlHessian(s.x, s.u, &euu);
  const double e = model.Energy(s.x, s.u);
  counter.Stop();
  EXPECT_EQ(counter.mallocs(), 0);
  // The fused passes, the band assembly and AcceptState, both with the frames of the
  // last pass (at its state) and computing them (right after another AcceptState).
  const int b = model.HessianBandwidth();
  std::vector<double> band(static_cast<size_t>(model.NumStates()) * (b + 1));
  double e_band = 0.0;
  test_support::AllocationCounter fused;
  model.ControlDerivatives(s.x, s.u, &eu, &exu, &euu);
  const bool banded = model.EnergyGradientAndBandHessian(s.x, s.u, &g, band.data(), b, &e_band);
  model.AcceptState(s.x, s.u);
  model.Gradient(s.x, s.u, &g);
  model.AcceptState(s.x, s.u);
  model.AcceptState(s.x, s.u);
  fused.Stop();
  EXPECT_TRUE(banded);
  EXPECT_EQ(fused.mallocs(), 0);
  EXPECT_TRUE(std::isfinite(e));
  EXPECT_EQ((Mat(h) - first).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(model.HessianBandwidth(), 10);  // a vertex spans nodes i-1 .. i+1
}

// Rotating and translating everything (clamp, grasp, nodes, and the lagged frames by
// accepting the rotated earlier state) leaves the energy unchanged.
TEST(RodModel, EnergyIsInvariantUnderRigidMotion) {
  std::mt19937 rng(99);
  const RodParams pa = BentRodParams(7);
  const M3 q = Eigen::AngleAxisd(2.1, V3(-0.3, 0.8, 0.5).normalized()).toRotationMatrix();
  const V3 shift(0.7, -1.2, 2.5);
  RodParams pb = pa;
  pb.clamp_position = q * pa.clamp_position + shift;
  pb.clamp_rotation = q * pa.clamp_rotation;
  pb.grasp_rotation = q * pa.grasp_rotation;
  RodModel a(pa), b(pb);
  auto move = [&](const RandomState& s) {
    RandomState r = s;
    for (int k = 2; k <= pa.n - 2; ++k) r.x.segment<3>(b.NodeIndex(k)) = q * s.x.segment<3>(a.NodeIndex(k)) + shift;
    r.u.head<3>() = q * s.u.head<3>() + shift;
    r.u.segment<3>(3) = q * s.u.segment<3>(3);  // exp([Qφ]×) = Q exp([φ]×) Qᵀ
    return r;
  };
  for (int trial = 0; trial < 3; ++trial) {
    const RandomPair pair = RandomBentPair(a, &rng);
    a.AcceptState(pair.older.x, pair.older.u);
    b.AcceptState(move(pair.older).x, move(pair.older).u);
    const RandomState nb = move(pair.newer);
    const double ea = a.Energy(pair.newer.x, pair.newer.u);
    EXPECT_GT(ea, 1e-3);
    EXPECT_NEAR(b.Energy(nb.x, nb.u), ea, 1e-11 * ea);
    EXPECT_NEAR(b.Probe(nb.x, nb.u), a.Probe(pair.newer.x, pair.newer.u), 1e-12);
    // Forces rotate with the motion.
    Vec eua, eub;
    a.ControlGradient(pair.newer.x, pair.newer.u, &eua);
    b.ControlGradient(nb.x, nb.u, &eub);
    EXPECT_LT((q * eua.head<3>() - eub.head<3>()).norm(), 1e-9 * std::max(1.0, eua.norm()));
  }
}


// The torque convention of rod_model.h: the world torque on the hand, -dE/dδ for a small
// rotation exp([δ]×) applied to the grasp orientation, is -J_l(φ)^{-T} E_φ (and -E_φ at φ = 0),
// and GraspTorqueCapability::GraspTorque gives it directly, also at |φ| = 2π where J_l is singular.
V3 CentralDifferenceTorque(const Model& model, const Vec& x, const Vec& u) {
  const M3 r = rod::ExpMap(u.segment<3>(3));
  const double h = 1e-6;
  V3 torque;
  for (int c = 0; c < 3; ++c) {
    double e[2];
    for (int side = 0; side < 2; ++side) {
      const V3 delta = (side == 0 ? h : -h) * V3::Unit(c);
      const Eigen::AngleAxisd rotated(rod::ExpMap(delta) * r);
      Vec v = u;
      v.segment<3>(3) = rotated.angle() * rotated.axis();
      e[side] = model.Energy(x, v);
    }
    torque[c] = -(e[0] - e[1]) / (2 * h);
  }
  return torque;
}

TEST(RodModel, TorqueIsTheConvertedRotationGradient) {
  std::mt19937 rng(11);
  RodModel model(BentRodParams(6));
  const RandomState s = RandomBentState(&model, &rng);
  Vec eu;
  model.ControlGradient(s.x, s.u, &eu);
  const V3 phi = s.u.segment<3>(3);
  const double a = phi.norm();
  const M3 k = rod::Cross(phi);
  const M3 jl = M3::Identity() + (1.0 - std::cos(a)) / (a * a) * k +
                (a - std::sin(a)) / (a * a * a) * k * k;
  const V3 torque = -jl.transpose().inverse() * eu.segment<3>(3);
  const V3 fd = CentralDifferenceTorque(model, s.x, s.u);
  V3 direct;
  model.GraspTorque(s.x, s.u, &direct);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(torque[c], fd[c], 1e-6 * std::max(1.0, torque.norm()));
    EXPECT_NEAR(direct[c], fd[c], 1e-6 * std::max(1.0, torque.norm()));
  }
  EXPECT_GT(torque.norm(), 1e-2);
  // The same orientation written as φ + 2π φ/|φ|: J_l(φ) is singular at |φ| = 2π, so
  // E_φ has lost the torque across the axis; GraspTorque has not.
  Vec turned = s.u;
  turned.segment<3>(3) = (1.0 + 2.0 * std::numbers::pi / a) * phi;
  model.GraspTorque(s.x, turned, &direct);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(direct[c], fd[c], 1e-6 * std::max(1.0, fd.norm()));
  Vec at_turn = s.u;
  at_turn.segment<3>(3) = 2.0 * std::numbers::pi * phi / a;
  const V3 fd_turn = CentralDifferenceTorque(model, s.x, at_turn);
  model.GraspTorque(s.x, at_turn, &direct);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(direct[c], fd_turn[c], 1e-6 * std::max(1.0, fd_turn.norm()));
}

// Accepting a state moves the reference frames without changing the energy there, and an
// equilibrium stays one (the energy of the physical rod does not depend on the frames).
TEST(RodModel, AcceptStateKeepsEnergyAndEquilibria) {
  std::mt19937 rng(5);
  RodModel model(BentRodParams(9));
  const RandomState s = RandomBentState(&model, &rng);
  const double e0 = model.Energy(s.x, s.u);
  const Vec theta0 = model.MaterialAngles(s.x, s.u);
  model.AcceptState(s.x, s.u);
  EXPECT_NEAR(model.Energy(s.x, s.u), e0, 1e-12 * e0);
  EXPECT_LT((model.MaterialAngles(s.x, s.u) - theta0).norm(), 1e-12);

  SolverOptions options;
  options.cutoff = 1e-10;
  EquilibriumTracker tracker(std::make_unique<RodModel>(BentRodParams(9)), options);
  Vec u = RandomBentPair(model, &rng).older.u;
  u.segment<3>(3).setZero();
  tracker.Reset(u);
  Vec g;
  for (int k = 1; k <= 30; ++k) {
    u[3] += 0.05;  // roll and move the grasp
    u[1] += 0.003;
    const TrackResult& r = tracker.Update(u);
    ASSERT_TRUE(r.summary.IsConverged()) << r.summary.BriefReport();
    // The tracker has called AcceptState: the residual in the new frames is still tiny.
    tracker.model().Gradient(tracker.state(), u, &g);
    EXPECT_LT(g.norm(), 1e-8) << "step " << k;
  }
}

// ---------------------------------------------------------------------------------
// Greenhill: a straight rod of length 1 between a clamp and a grasp at distance 1 on its
// axis, the grasp rolled about that axis from 0 to 720° in 2000 steps.
constexpr double kGreenhill = 8.9868;  // M L / EI at the clamped-clamped twist buckling

struct GreenhillRun {
  double critical_twist = -1.0;  // Φ at the first instability (rad), -1 if none
  double torque_ratio = 0.0;     // |torque| / (GJ Φ / L) at Φ = Φ_c / 2
  double discrete_ratio = 0.0;   // |torque| / (GJ Φ / ((n - 1) ℓ)) there
  double final_probe = 0.0;
  int converged = 0;
  int steps = 0;
};

GreenhillRun RunGreenhill(int n, double twist_stiffness, const std::string& method, double offset,
                          int steps = 2000, double max_deg = 720.0,
                          bool stop_at_instability = false) {
  RodParams p;
  p.n = n;
  p.length = 1.0;
  p.stretch_stiffness = 1000.0;
  p.bend_stiffness = 1.0;
  p.bend_stiffness_2 = 1.0;
  p.twist_stiffness = twist_stiffness;
  SolverOptions options;
  options.method = method;
  options.cutoff = 1e-9;
  EquilibriumTracker tracker(std::make_unique<RodModel>(p), options);
  tracker.SetSnapThreshold(0.1 / n);
  // `offset` moves the grasp sideways (an imperfection: a perfectly straight rod is an
  // equilibrium at every twist, and Newton-type methods stay on it).
  Vec u(6);
  u << 1.0, offset, 0.0, 0.0, 0.0, 0.0;
  tracker.Reset(u);
  GreenhillRun run;
  std::vector<double> torque(steps + 1, 0.0);
  for (int k = 1; k <= steps; ++k) {
    const double roll = max_deg * std::numbers::pi / 180.0 * k / steps;
    u[3] = roll;
    const TrackResult& r = tracker.Update(u);
    torque[k] = r.force[3];
    run.converged += r.summary.IsConverged() ? 1 : 0;
    const bool unstable = r.summary.negative_pivots > 0 || r.summary.lambda_min < 0.0 ||
                          r.probe > 1e-4;
    if (unstable && run.critical_twist < 0.0) {
      run.critical_twist = roll;
      const int half = k / 2;
      const double roll_half = max_deg * std::numbers::pi / 180.0 * half / steps;
      run.torque_ratio = std::abs(torque[half]) / (twist_stiffness * roll_half / p.length);
      run.discrete_ratio = std::abs(torque[half]) /
                           (twist_stiffness * roll_half / ((n - 1) * p.length / n));
      if (stop_at_instability) break;
    }
    run.final_probe = r.probe;
  }
  run.steps = steps;
  return run;
}


// Φ_c converges to Greenhill's clamped-clamped value 8.9868 EI/GJ as n grows (the
// straight rod: the first negative pivot / eigenvalue of E_xx), and the torque before
// buckling is GJ Φ / L (exactly GJ Φ / ((n - 1) ℓ) in the discrete rod: the twist acts
// between the midpoints of the held edges).
TEST(RodGreenhill, CriticalTwistConvergesWithN) {
  double previous_error = 1.0;
  for (int n : {10, 20, 40}) {
    const GreenhillRun r = RunGreenhill(n, 1.0, "higher-order", 0.0, 2000, 720.0, true);
    ASSERT_GT(r.critical_twist, 0.0) << "n=" << n;
    const double error = std::abs(r.critical_twist / kGreenhill - 1.0);
    std::printf("Greenhill n=%d: Phi_c = %.4f rad, error %.2f%%, torque / (GJ Phi / L) = %.4f\n", n,
                r.critical_twist, 100.0 * error, r.torque_ratio);
    EXPECT_LT(error, previous_error) << "n=" << n;
    previous_error = error;
    EXPECT_NEAR(r.discrete_ratio, 1.0, 1e-6) << "n=" << n;
    EXPECT_NEAR(r.torque_ratio, 1.0, 1.5 / (n - 1)) << "n=" << n;
  }
  EXPECT_LT(previous_error, 0.05);
}

TEST(RodGreenhill, CriticalTwistHalvesWhenTwistStiffnessDoubles) {
  const GreenhillRun soft = RunGreenhill(20, 1.0, "higher-order", 0.0, 2000, 720.0, true);
  const GreenhillRun stiff = RunGreenhill(20, 2.0, "higher-order", 0.0, 2000, 720.0, true);
  ASSERT_GT(soft.critical_twist, 0.0);
  ASSERT_GT(stiff.critical_twist, 0.0);
  std::printf("Greenhill n=20: Phi_c(GJ=2) / Phi_c(GJ=1) = %.4f\n",
              stiff.critical_twist / soft.critical_twist);
  EXPECT_NEAR(stiff.critical_twist / soft.critical_twist, 0.5, 0.005);
}

// Past the buckle the rod bows out against its own stretching. A perfectly straight rod
// stays on the (unstable) straight branch under every method (it is an equilibrium at
// every twist), so the grasp sits 1e-6 L off the axis: the imperfection of a real rod.
class RodGreenhillMethods : public ::testing::TestWithParam<std::string> {};

TEST_P(RodGreenhillMethods, RodIsOutOfLineAfterTheBuckle) {
  const GreenhillRun r = RunGreenhill(20, 1.0, GetParam(), 1e-6);
  ASSERT_GT(r.critical_twist, 0.0);
  EXPECT_NEAR(r.critical_twist / kGreenhill, 1.0, 0.05);
  EXPECT_GT(r.final_probe, 0.02);
  EXPECT_EQ(r.converged, r.steps);
}

// Every registered method (newton, newton-ls, higher-order).
INSTANTIATE_TEST_SUITE_P(Methods, RodGreenhillMethods,
                         ::testing::ValuesIn(SolverRegistry::Global().Names()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& c : name) {
                             if (c == '-') c = '_';
                           }
                           return name;
                         });

}  // namespace
}  // namespace snapthread
