// The rod's drawing data (common/models/rod_shape.cc): material director m1 and twist
// density per edge, on straight rods twisted uniformly by a known angle.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include "models/rod_model.h"

namespace snapthread {
namespace {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

struct Twisted {
  Vec x, u;
};

// A straight rod along the clamp's body x axis whose grasp is rolled by `phi` about it, in
// `steps` accepted steps (so the material angles are continued past ±π as the solver's
// accepted states would), at the uniformly twisted state InitialState gives.
Twisted TwistStraight(RodModel* rod, double phi, int steps) {
  const RodParams& p = rod->params();
  const V3 axis = p.clamp_rotation.col(0);
  Twisted t;
  t.u = Vec::Zero(6);
  t.u.head<3>() = p.clamp_position + p.length * axis;
  for (int k = 1; k <= steps; ++k) {
    t.u.segment<3>(3) = (phi * k / steps) * axis;
    t.x = rod->InitialState(t.u);
    rod->AcceptState(t.x, t.u);
  }
  return t;
}

RodParams StraightParams(int n, const M3& rotation) {
  RodParams p;
  p.n = n;
  p.length = 1.3;
  p.clamp_position = V3(0.1, -0.2, 0.3);
  p.clamp_rotation = rotation;
  p.grasp_rotation = rotation;
  return p;
}

// Held edges turned by Φ against each other: the twist θ_{n−1} − θ_0 = Φ spreads evenly
// over the n − 1 interior vertices, Φ / (n − 1) at each, so the density is Φ / ((n − 1) ℓ)
// on every edge (the continuum Φ / L with the twisted length between the held edges'
// midpoints), and m1 of edge j is turned by Φ j / (n − 1) from the clamp's m1.
TEST(RodShape, UniformTwistHasConstantDensityAndTurningDirector) {
  const M3 rotations[] = {M3::Identity(),
                          Eigen::AngleAxisd(0.4, V3(1, 2, 3).normalized()).toRotationMatrix()};
  for (const M3& r : rotations) {
    for (const double phi : {0.0, 2.0, -2.0, 3.0 * std::numbers::pi}) {
      const int n = 12;
      RodModel rod(StraightParams(n, r));
      const Twisted t = TwistStraight(&rod, phi, 24);
      Eigen::Matrix3Xd d1;
      Vec density;
      rod.MaterialFrames(t.x, t.u, &d1, &density);
      ASSERT_EQ(d1.cols(), n);
      ASSERT_EQ(density.size(), n);
      const double ell = rod.params().length / n;
      const double want = phi / ((n - 1) * ell);
      for (int j = 0; j < n; ++j) {
        EXPECT_NEAR(density[j], want, 1e-9 * (1.0 + std::abs(want))) << "edge " << j << " phi " << phi;
        const double angle = phi * j / (n - 1);
        const V3 m1 = std::cos(angle) * r.col(1) + std::sin(angle) * r.col(2);
        EXPECT_LT((d1.col(j) - m1).norm(), 1e-9) << "edge " << j << " phi " << phi;
        EXPECT_LT((d1.col(j) - rod.MaterialDirector(t.x, t.u, j)).norm(), 1e-12);
      }
      EXPECT_LT((rod.TwistDensity(t.x, t.u) - density).norm(), 1e-12);
    }
  }
}

// The density is the twist alone: a bent but untwisted rod (the grasp moved sideways, no
// roll; the ends held parallel) has the reference twist of its planar bend, which is zero.
TEST(RodShape, PlanarBendIsNotTwist) {
  RodModel rod(StraightParams(10, M3::Identity()));
  Vec u = Vec::Zero(6);
  u.head<3>() = rod.params().clamp_position + V3(1.1, 0.3, 0.0);
  const Vec x = rod.InitialState(u);  // bowed in the clamp's x-y plane (towards its m1)
  const Vec density = rod.TwistDensity(x, u);
  for (int j = 0; j < 10; ++j) EXPECT_NEAR(density[j], 0.0, 1e-12) << "edge " << j;
  EXPECT_GT(rod.Probe(x, u), 0.05);  // it is bent
}

}  // namespace
}  // namespace snapthread
