#include "models/contact_terms.h"

#include <limits>
#include <stdexcept>

namespace snapthread::internal {

std::vector<ParamSpec> ContactParamSpecs() {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  return {
      {.name = "contact", .kind = ParamKind::kBool, .default_value = 0.0,
       .doc = "self-contact: capsules of `radius` never pass through each other (IPC barrier)"},
      {.name = "contact_distance", .default_value = 0.005, .min = 0.0, .min_inclusive = false,
       .max = kInf, .units = "model length",
       .doc = "activation gap d-hat between the capsules' surfaces of the contact barrier"},
      {.name = "contact_stiffness", .default_value = 0.01, .min = 0.0, .min_inclusive = false,
       .max = kInf, .units = "model energy", .doc = "kappa of the contact barrier kappa b(d^2)"},
  };
}

contact::ContactParams ReadContactParams(const ModelParams& params) {
  contact::ContactParams p;
  p.enabled = params.Bool("contact");
  p.radius = params.Number("radius");
  p.dhat = params.Number("contact_distance");
  p.stiffness = params.Number("contact_stiffness");
  return p;
}

void ContactTerms::Register(const contact::ContactParams& params, int segments, double rest_length,
                            const std::function<NodeCoord(int, int)>& code, HessianAssembly* assembly) {
  if (!params.enabled) return;
  self_ = contact::SelfContact(params, segments, rest_length);
  assembly_ = assembly;
  segments_ = segments;
  coords_.resize(3 * (segments + 1));
  node_controls_.assign(segments + 1, 0);
  for (int k = 0; k <= segments; ++k) {
    for (int c = 0; c < 3; ++c) {
      coords_[3 * k + c] = code(k, c);
      if (coords_[3 * k + c].control >= 0) node_controls_[k] = 1;
    }
  }
  pair_term_.assign(static_cast<size_t>(segments) * segments, -1);
  set_.clear();
  assembly->EnableDynamicTerms();
}

bool ContactTerms::CoverActive(const Eigen::Matrix3Xd& nodes) const {
  if (!enabled()) return false;
  const double reach = self_.params().ActivationDistance();
  self_.PairsWithin(nodes, reach, &scratch_pairs_);
  bool missing = false;
  for (const auto& [i, j] : scratch_pairs_) missing = missing || pair_term_[i * segments_ + j] < 0;
  if (!missing) return false;
  // A pair active here is not in the set: the set becomes the pairs within the
  // activation distance plus the margin, so that the next few steps find theirs in it.
  self_.PairsWithin(nodes, (1.0 + kMargin) * reach, &scratch_pairs_);
  for (const auto& [i, j] : set_) pair_term_[i * segments_ + j] = -1;
  set_ = scratch_pairs_;  // a copy: the scratch keeps its capacity (no allocation when warm)
  term_vars_.clear();
  term_begin_.assign(1, 0);
  for (const auto& [i, j] : set_) {
    for (int r = 0; r < 12; ++r) {
      const NodeCoord& nc = Coord(Node(i, j, r), r % 3);
      if (nc.state >= 0) term_vars_.push_back(nc.state);
    }
    term_begin_.push_back(static_cast<int>(term_vars_.size()));
  }
  assembly_->SetDynamicTerms(term_vars_, term_begin_);
  for (size_t k = 0; k < set_.size(); ++k) {
    pair_term_[set_[k].first * segments_ + set_[k].second] = assembly_->FixedTerms() + static_cast<int>(k);
  }
  ++rebuilds_;
  return true;
}

template <class F>
void ContactTerms::ForEach(const Eigen::Matrix3Xd& nodes, bool want_h, bool controls_only, F&& f) const {
  if (!enabled()) return;
  const bool feasible = self_.ForEachActive(nodes, want_h, [&](int i, int j, const contact::Vec12& g12,
                                                               const contact::Mat12& h12) {
    if (controls_only &&
        !(node_controls_[i] || node_controls_[i + 1] || node_controls_[j] || node_controls_[j + 1]))
      return;
    f(i, j, g12, h12);
  });
  if (!feasible) {
    // Touching capsules: no finite derivative. Non-finite outputs make the solvers
    // restore their last good state and report it (model.h).
    const contact::Vec12 nan = contact::Vec12::Constant(std::numeric_limits<double>::quiet_NaN());
    f(-1, -1, nan, contact::Mat12::Constant(nan[0]));
  }
}

void ContactTerms::AddGradient(const Eigen::Matrix3Xd& nodes, double* g) const {
  ForEach(nodes, false, false, [&](int i, int j, const contact::Vec12& g12, const contact::Mat12&) {
    if (i < 0) {
      g[0] = g12[0];
      return;
    }
    for (int r = 0; r < 12; ++r) {
      const NodeCoord& nc = Coord(Node(i, j, r), r % 3);
      if (nc.state >= 0) g[nc.state] += g12[r];
    }
  });
}

void ContactTerms::AddHessian(const Eigen::Matrix3Xd& nodes, double* values) const {
  ForEach(nodes, true, false, [&](int i, int j, const contact::Vec12&, const contact::Mat12& h12) {
    const int term = i < 0 ? -1 : pair_term_[i * segments_ + j];
    if (term < 0) {
      // Touching capsules, or an active pair the pattern lacks (CoverActive() was not
      // called at these nodes): no valid E_xx.
      values[0] = std::numeric_limits<double>::quiet_NaN();
      return;
    }
    if (assembly_->TermSize(term) == 12) {
      // Twelve state coordinates, in order: the pair's derivatives are the term's.
      assembly_->AddHessian(term, h12.data(), 12, values);
      return;
    }
    // The rows and columns of the state coordinates, in the term's order.
    int rows[12];
    int k = 0;
    for (int r = 0; r < 12; ++r) {
      if (Coord(Node(i, j, r), r % 3).state >= 0) rows[k++] = r;
    }
    contact::Mat12 local;
    for (int b = 0; b < k; ++b) {
      for (int a = 0; a < k; ++a) local(a, b) = h12(rows[a], rows[b]);
    }
    assembly_->AddHessian(term, local.data(), 12, values);
  });
}

void ContactTerms::AddControlGradient(const Eigen::Matrix3Xd& nodes, const ControlMap& cmap, double* eu) const {
  const int nu = assembly_ != nullptr ? assembly_->NumControls() : 0;
  ForEach(nodes, false, true, [&](int i, int j, const contact::Vec12& g12, const contact::Mat12&) {
    if (i < 0) {
      eu[0] = g12[0];
      return;
    }
    for (int r = 0; r < 12; ++r) {
      const int row = Coord(Node(i, j, r), r % 3).control;
      if (row < 0) continue;
      for (int c = 0; c < nu; ++c) eu[c] += g12[r] * cmap.jac(row, c);
    }
  });
}

void ContactTerms::AddMixedHessian(const Eigen::Matrix3Xd& nodes, const ControlMap& cmap, Mat* exu) const {
  const int nu = assembly_ != nullptr ? assembly_->NumControls() : 0;
  ForEach(nodes, true, true, [&](int i, int j, const contact::Vec12&, const contact::Mat12& h12) {
    if (i < 0) {
      (*exu)(0, 0) = h12(0, 0);
      return;
    }
    // E_xu = D_x-rows of h12 times the controlled coordinates' Jacobian rows.
    for (int r = 0; r < 12; ++r) {
      const int s = Coord(Node(i, j, r), r % 3).state;
      if (s < 0) continue;
      for (int q = 0; q < 12; ++q) {
        const int row = Coord(Node(i, j, q), q % 3).control;
        if (row < 0) continue;
        for (int c = 0; c < nu; ++c) (*exu)(s, c) += h12(r, q) * cmap.jac(row, c);
      }
    }
  });
}

void ContactTerms::AddControlHessian(const Eigen::Matrix3Xd& nodes, const ControlMap& cmap, Mat* euu) const {
  const int nu = assembly_ != nullptr ? assembly_->NumControls() : 0;
  ForEach(nodes, true, true, [&](int i, int j, const contact::Vec12& g12, const contact::Mat12& h12) {
    if (i < 0) {
      (*euu)(0, 0) = h12(0, 0);
      return;
    }
    // E_uu = Jᵀ h12 J + Σ_r g_r (d²y_r/du²) over the controlled coordinates y_r.
    Eigen::Matrix<double, 12, ControlMap::kControls> jac = Eigen::Matrix<double, 12, ControlMap::kControls>::Zero();
    for (int r = 0; r < 12; ++r) {
      const int row = Coord(Node(i, j, r), r % 3).control;
      if (row < 0) continue;
      jac.row(r) = cmap.jac.row(row);
      euu->topLeftCorner(nu, nu) += g12[r] * cmap.hess[row].topLeftCorner(nu, nu);
    }
    const Eigen::Matrix<double, 12, ControlMap::kControls> hj = h12 * jac;
    euu->topLeftCorner(nu, nu) += (jac.transpose() * hj).topLeftCorner(nu, nu);
  });
}

}  // namespace snapthread::internal
