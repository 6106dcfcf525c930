// Continuous collision detection of two capsules (segments of radius r): how far along
// a straight motion of their four endpoints they can go without their surfaces meeting.
//
// Additive CCD (Li, Kaufman and Jiang 2021, "Codimensional Incremental Potential
// Contact", Algorithm 1): remove the mean displacement (a common translation changes no
// distance), bound the closing speed of the two closest points by
// l_p = max |Δa_i| + max |Δb_j|, and advance by steps that provably cannot close more
// than 0.9 of the current gap, until the gap falls below `keep` times its starting
// value. Conservative: every state on [0, t] keeps the gap above 0.1 of a gap seen along
// the way, so the surfaces never touch, and the gap at t is at least keep times the
// starting gap. Only distance evaluations; no root finding, no round-off tunnelling.
#pragma once

#include <Eigen/Core>

namespace snapthread::contact {

// The largest t in [0, t_max] found for the motion a0 + τ da0, ... (τ in [0, t]) of the
// segments (a0, a1) and (b0, b1) with centrelines touching at `contact_distance` (2r),
// keeping the gap d - 2r above `keep` (in (0, 1)) of its value at τ = 0. 0 when the
// capsules already touch or overlap. At most `max_iterations` advances; when they are
// used up the t reached so far is returned (still conservative).
double CapsuleCcd(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& b0,
                  const Eigen::Vector3d& b1, const Eigen::Vector3d& da0, const Eigen::Vector3d& da1,
                  const Eigen::Vector3d& db0, const Eigen::Vector3d& db1, double contact_distance,
                  double keep, double t_max = 1.0, int max_iterations = 200);

}  // namespace snapthread::contact
