// Self-contact of the rod: the barrier pairs of models/contact_terms.h on the
// rod's nodes. Clamped nodes x_0, x_1 are fixed and x_{n-1}, x_n follow the grasp
// u = (p, φ) (ControlMap rows 0..2 and 3..5); without a clamp x_0, x_1 follow the first
// grasp u[0..5] (rows 0..2, 3..5) and x_{n-1}, x_n the second u[6..11] (rows 6..8,
// 9..11). The other nodes are state variables.
#include "models/rod_model.h"

namespace snapthread {

void RodModel::RegisterContact() {
  contact::ContactParams cp = p_.contact;
  cp.radius = p_.radius;
  contact_.Register(cp, n_, rest_,
                    [&](int k, int c) {
                      internal::NodeCoord nc;
                      const int end = p_.free_start ? 6 : 0;
                      if (k == n_ - 1) nc.control = end + c;
                      else if (k == n_) nc.control = end + 3 + c;
                      else if (k >= 2) nc.state = NodeIndex(k) + c;
                      else if (p_.free_start) nc.control = 3 * k + c;  // x_0, x_1
                      return nc;
                    },
                    &assembly_);
}

const Eigen::Matrix3Xd& RodModel::ContactNodes(const Vec& x, const GraspMaps& gm) const {
  if (contact_nodes_.cols() != n_ + 1) contact_nodes_.resize(3, n_ + 1);
  for (int k = 0; k <= n_; ++k) contact_nodes_.col(k) = Node(k, x, gm);
  return contact_nodes_;
}

internal::ControlMap RodModel::ContactControls(const GraspMaps& gms) const {
  internal::ControlMap m;
  for (auto& h : m.hess) h.setZero();
  // One grasp's map (rows 0..2 the inner node, 3..5 the held one, over its (p, φ) at
  // control column `col`) into the rows of its held node `held` and inner node `inner`.
  auto put = [&](const GraspMap& gm, int held, int inner, int col) {
    for (int c = 0; c < 3; ++c) {
      m.jac.block<1, 6>(inner + c, col) = gm.jac.row(c);
      m.jac.block<1, 6>(held + c, col) = gm.jac.row(3 + c);
      m.hess[inner + c].block<3, 3>(col + 3, col + 3) = gm.hess_phi[c];  // linear in p
    }
  };
  if (p_.free_start) {
    put(gms.start, 0, 3, 0);  // x_0 held, x_1 inner: u[0..5]
    put(gms.end, 9, 6, 6);    // x_n held, x_{n-1} inner: u[6..11]
  } else {
    put(gms.end, 3, 0, 0);
  }
  return m;
}

double RodModel::MaxStepFraction(const Vec& x, const Vec& dx, const Vec& u) const {
  if (!contact_.enabled()) return 1.0;
  contact_trial_ = x + dx;
  return MaxMotionFraction(x, u, contact_trial_, u);
}

double RodModel::MaxMotionFraction(const Vec& x0, const Vec& u0, const Vec& x1, const Vec& u1) const {
  if (!contact_.enabled()) return 1.0;
  const GraspMaps g0 = Grasp(u0, false), g1 = Grasp(u1, false);
  Eigen::Matrix3Xd& from = contact_nodes_;
  ContactNodes(x0, g0);
  Eigen::Matrix3Xd& to = contact_to_;
  if (to.cols() != n_ + 1) to.resize(3, n_ + 1);
  for (int k = 0; k <= n_; ++k) to.col(k) = Node(k, x1, g1);
  return contact_.self().MaxStepFraction(from, to);
}

std::vector<contact::ContactPoint> RodModel::ActiveContacts(const Vec& x, const Vec& u) const {
  if (!contact_.enabled()) return {};
  Eigen::Matrix3Xd nodes;
  NodePositions(x, u, &nodes);
  return contact_.self().ActivePairs(nodes);
}

}  // namespace snapthread
