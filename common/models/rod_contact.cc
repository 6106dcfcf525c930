// Self-contact of the rod (issue 15): the barrier pairs of models/contact_terms.h on the
// rod's nodes. Clamped nodes x_0, x_1 are fixed, x_{n-1} and x_n follow the grasp
// u = (p, φ) (rows 0..2 and 3..5 of the grasp map), the others are state variables.
#include "models/rod_model.h"

namespace snapthread {

void RodModel::RegisterContact() {
  contact::ContactParams cp = p_.contact;
  cp.radius = p_.radius;
  contact_.Register(cp, n_, rest_,
                    [&](int k, int c) {
                      internal::NodeCoord nc;
                      if (k == n_ - 1) nc.control = c;
                      else if (k == n_) nc.control = 3 + c;
                      else if (k >= 2) nc.state = NodeIndex(k) + c;
                      return nc;
                    },
                    &assembly_);
}

const Eigen::Matrix3Xd& RodModel::ContactNodes(const Vec& x, const GraspMaps& gm) const {
  if (contact_nodes_.cols() != n_ + 1) contact_nodes_.resize(3, n_ + 1);
  for (int k = 0; k <= n_; ++k) contact_nodes_.col(k) = Node(k, x, gm);
  return contact_nodes_;
}

internal::ControlMap RodModel::ContactControls(const GraspMaps& gms) {
  const GraspMap& gm = gms.end;  // a clamped rod: the one grasp, of edge n-1
  internal::ControlMap m;
  m.jac = gm.jac.topRows<6>();
  for (int r = 0; r < 6; ++r) {
    m.hess[r].setZero();
    m.hess[r].bottomRightCorner<3, 3>() = gm.hess_phi[r];  // linear in p
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
