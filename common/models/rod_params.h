// The discrete elastic rod's parameters (rod_model.h): geometry, stiffnesses, clamp and grasp.
#pragma once

#include <string>

#include <Eigen/Core>

#include "contact/barrier.h"

namespace snapthread {

struct RodParams {
  int n = 10;                       // edges (≥ 3)
  double length = 1.0;              // rest length L (m); every edge ℓ = L / n
  double stretch_stiffness = 1000;  // EA (N)
  double bend_stiffness = 1.0;      // B1 = EI about m2, for κ1 (N m²)
  double bend_stiffness_2 = 1.0;    // B2 about m1, for κ2 (N m²)
  double twist_stiffness = 1.0;     // GJ (N m²)
  double natural_curvature = 0.0;   // κ̄1 (1/m), bending towards m1
  double natural_curvature_2 = 0.0; // κ̄2 (1/m), bending towards m2
  double radius = 0.01;             // tube radius: drawing, and contact (m)
  // Self-contact: capsules of `radius` with IPC's barrier; off by default.
  // contact.radius is ignored: `radius` is the capsule radius.
  contact::ContactParams contact{};
  Eigen::Vector3d clamp_position = Eigen::Vector3d::Zero();
  Eigen::Matrix3d clamp_rotation = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d grasp_rotation = Eigen::Matrix3d::Identity();  // R_start (φ = 0)
  // No clamp: edge 0 is held by a first grasp u[0..5] = (p, φ) with
  // x_0 = p, x_1 = p + ℓ R e_x, R = exp([φ]×) clamp_rotation, m1_0 = R e_y, and the
  // grasp above takes u[6..11]. Both ends held by full poses leave no rigid-body motion.
  bool free_start = false;

  bool IsValid(std::string* error) const;
};

}  // namespace snapthread
