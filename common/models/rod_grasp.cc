// The rod's grasp maps u -> (x_{n-1}, x_n, θ_{n-1}) (and, without a clamp, the first
// grasp's u -> (x_1, x_0, θ_0)) with exact first and second derivatives in the rotation
// vector (rod_model.h, rod_frames.h), and their cache per update.
#include <cmath>
#include <cstring>
#include <numbers>

#include "models/rod_model.h"

namespace snapthread {

using rod::FrameSource;
using rod::Jet;
using rod::JetVec;
using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

RodModel::GraspMaps RodModel::Grasp(const Vec& u, bool derivatives, bool world_rotation) const {
  GraspMaps gm;
  gm.end = OneGrasp(u, false, derivatives, world_rotation);
  if (p_.free_start) gm.start = OneGrasp(u, true, derivatives, world_rotation);
  return gm;
}

const RodModel::GraspMaps& RodModel::GraspDerivatives(const Vec& u) const {
  // The maps depend on u and on the lagged frames, which only AcceptState and
  // ResetHistory move (they clear grasp_cache_valid_): equal bits of u, the same maps.
  if (!grasp_cache_valid_ || u.size() != grasp_cache_u_.size() ||
      std::memcmp(u.data(), grasp_cache_u_.data(), sizeof(double) * u.size()) != 0) {
    grasp_cache_valid_ = false;
    grasp_cache_.end = OneGrasp(u, false, true, false);
    if (p_.free_start) grasp_cache_.start = OneGrasp(u, true, true, false);
    grasp_cache_u_ = u;  // sized nu_ at construction: no allocation
    grasp_cache_valid_ = true;
  }
  return grasp_cache_;
}

// The held end node is xn (x_n, or x_0 for the grasp of edge 0), the inner one xn1
// (x_{n-1}, or x_1): the edge's tangent t = R e_x points from x_{n-1} to x_n and from x_0
// to x_1, so the inner node is the held one ∓ ℓ t.
RodModel::GraspMap RodModel::OneGrasp(const Vec& u, bool at_start, bool derivatives,
                                      bool world_rotation) const {
  GraspMap gm;
  const int offset = p_.free_start && !at_start ? 6 : 0;
  const V3 pos = u.segment<3>(offset);
  const V3 phi = u.segment<3>(offset + 3);
  const M3& r_start = at_start ? p_.clamp_rotation : p_.grasp_rotation;
  const double side = at_start ? rest_ : -rest_;
  const FrameSource& src = sources_[at_start ? 0 : n_ - 1];
  const double near = at_start ? start_theta_near_ : grasp_theta_near_;
  // Values (the same with or without derivatives): the rotation and one angle.
  const M3 r = rod::ExpMap(phi) * r_start;
  {
    const V3 t = r.col(0);
    gm.xn = pos;
    gm.xn1 = pos + side * t;
    V3 a, b;
    rod::ReferenceFrame(src, t, &a, &b);
    gm.theta = rod::AngleAbout(t, a, r.col(1), near);
  }
  if (!derivatives) return gm;
  // Derivatives in φ, or in a world rotation δ of the current orientation
  // (exp([δ]×) R(u), δ = 0) for the torque.
  const M3& rot = world_rotation ? r : r_start;
  const V3 at = world_rotation ? V3::Zero() : phi;
  const JetVec t = rod::RotateJet(at, rot.col(0));
  const JetVec m1 = rod::RotateJet(at, rot.col(1));
  // θ_{n-1}: the angle of m1 about t from the time-parallel reference director
  // a = P_{t_s}^{t} a_s = a_s - (a_s·t)/(1 + t_s·t) (t_s + t) (a_s ⊥ t_s).
  const FrameSource& s = src;
  const Jet k = Dot(s.a, t) * rod::Inverse(Jet::Constant(1.0) + Dot(s.t, t));
  const JetVec a = JetVec::Constant(s.a) - k * (JetVec::Constant(s.t) + t);
  const JetVec b = rod::CrossJ(t, a);
  const Jet theta = rod::Atan2(Dot(b, m1), Dot(a, m1));
  gm.jac.setZero();
  for (int c = 0; c < 3; ++c) {
    gm.jac(c, c) = 1.0;
    gm.jac(3 + c, c) = 1.0;
    gm.jac.block<1, 3>(c, 3) = side * t.c[c].g.transpose();
    gm.hess_phi[c] = side * t.c[c].h;
    gm.hess_phi[3 + c].setZero();
  }
  gm.jac.block<1, 3>(6, 3) = theta.g.transpose();
  gm.hess_phi[6] = theta.h;
  return gm;
}

}  // namespace snapthread
