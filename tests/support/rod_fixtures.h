// Rods for the discrete elastic rod's tests (rod_test.cc, rod_evaluate_test.cc,
// grasps_test.cc): parameters with nothing symmetric about them (unequal bending
// stiffnesses, natural curvature in both directions, clamp and grasp turned), so that no
// wrong derivative term can cancel, and random bent and twisted states. Header-only: for
// the test binaries that link the models (common/models).
#pragma once

#include <random>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "models/rod_model.h"
#include "numeric/types.h"

namespace snapthread::test_support {

// A ribbon-like rod (B2 = 2.7 B1) with natural curvature, clamped at a moved and turned
// clamp, the grasp turned against it.
inline RodParams BentRodParams(int n) {
  using V3 = Eigen::Vector3d;
  RodParams p{.n = n, .length = 1.3, .stretch_stiffness = 50.0, .bend_stiffness = 1.0,
              .bend_stiffness_2 = 2.7, .twist_stiffness = 0.8, .natural_curvature = 0.9,
              .natural_curvature_2 = -0.4, .clamp_position = V3(0.1, -0.2, 0.3),
              .clamp_rotation = Eigen::AngleAxisd(0.4, V3(1, 2, 3).normalized()).toRotationMatrix()};
  p.grasp_rotation = Eigen::AngleAxisd(-0.3, V3(0, 1, 1).normalized()).toRotationMatrix() * p.clamp_rotation;
  return p;
}

// A rod without a clamp (free_start): both ends held by grasps, the first grasp's frame
// (clamp_rotation) and the second's (grasp_rotation) turned.
inline RodParams FreeRodParams(int n) {
  using V3 = Eigen::Vector3d;
  return {.n = n, .length = 1.1, .stretch_stiffness = 60.0, .bend_stiffness = 1.0,
          .bend_stiffness_2 = 1.9, .twist_stiffness = 0.7, .natural_curvature = 0.6,
          .natural_curvature_2 = -0.2,
          .clamp_rotation = Eigen::AngleAxisd(0.5, V3(1, -1, 2).normalized()).toRotationMatrix(),
          .grasp_rotation = Eigen::AngleAxisd(-0.4, V3(0, 1, 1).normalized()).toRotationMatrix(),
          .free_start = true};
}

struct RodState {
  Vec x, u;
};

// (x0, u0) with the nodes moved by up to 0.2 edge lengths, the angles by up to 0.6 rad,
// the grasp moved by up to 0.2 edge lengths and rolled by up to 0.2 rad.
inline RodState Perturbed(const RodModel& model, const Vec& x0, const Vec& u0, std::mt19937* rng) {
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  RodState s{x0, u0};
  const double l = model.params().length / model.params().n;
  for (int i = 0; i < s.x.size(); ++i) s.x[i] += 0.2 * l * d(*rng);
  for (int j = 1; j <= model.params().n - 2; ++j) s.x[model.ThetaIndex(j)] += 0.6 * d(*rng);
  for (int c = 0; c < 3; ++c) s.u[c] += 0.2 * l * d(*rng);
  for (int c = 3; c < 6; ++c) s.u[c] += 0.2 * d(*rng);
  return s;
}

struct RodStatePair {
  RodState older, newer;
};

// Two random bent and twisted states of a clamped rod, the newer perturbed from the older
// (the grasp 0.8 L out along the clamp, moved off the line and rolled).
inline RodStatePair RandomBentPair(const RodModel& model, std::mt19937* rng) {
  const RodParams& p = model.params();
  Vec u(6);
  u << p.clamp_position + 0.8 * p.length * p.clamp_rotation.col(0) +
           Eigen::Vector3d(0.05, 0.2, -0.1) * p.length,
      0.3, -0.5, 1.2;
  RodStatePair pair;
  pair.older = Perturbed(model, model.InitialState(u), u, rng);
  pair.newer = Perturbed(model, pair.older.x, pair.older.u, rng);
  return pair;
}

// The lagged frames accepted at one random state, the other returned: evaluated there, the
// twist-rate terms of the reference frames are not zero.
inline RodState RandomBentState(RodModel* model, std::mt19937* rng) {
  const RodStatePair pair = RandomBentPair(*model, rng);
  model->AcceptState(pair.older.x, pair.older.u);
  return pair.newer;
}

}  // namespace snapthread::test_support
