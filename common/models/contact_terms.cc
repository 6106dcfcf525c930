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
  for (int k = 0; k <= segments; ++k) {
    for (int c = 0; c < 3; ++c) coords_[3 * k + c] = code(k, c);
  }
  pair_term_.assign(segments * segments, -1);
  pair_controls_.assign(segments * segments, 0);
  pair_direct_.assign(segments * segments, 0);
  const int nx = assembly->NumStates(), nu = assembly->NumControls();
  for (int i = 0; i < segments; ++i) {
    for (int j = i + self_.MinIndexGap(); j < segments; ++j) {
      int vars[kMaxVars + 12];
      int count = 0;
      bool controls = false;
      for (int node : {i, i + 1, j, j + 1}) {
        for (int c = 0; c < 3; ++c) {
          const NodeCoord& nc = coords_[3 * node + c];
          if (nc.state >= 0) vars[count++] = nc.state;
          controls = controls || nc.control >= 0;
        }
      }
      const bool direct = count == 12;
      if (controls) {
        for (int c = 0; c < nu; ++c) vars[count++] = nx + c;
      }
      if (count > kMaxVars) throw std::logic_error("contact term with too many variables");
      pair_term_[i * segments + j] = assembly->AddTerm(vars, count);
      pair_controls_[i * segments + j] = controls ? 1 : 0;
      pair_direct_[i * segments + j] = direct ? 1 : 0;
    }
  }
}

template <class F>
void ContactTerms::ForEach(const Eigen::Matrix3Xd& nodes, const ControlMap* cmap, bool want_h,
                           bool controls_only, F&& f) const {
  if (!enabled()) return;
  const int nu = assembly_->NumControls();
  const bool feasible = self_.ForEachActive(nodes, want_h, [&](int i, int j, const contact::Vec12& g12,
                                                               const contact::Mat12& h12) {
    const int pair = i * segments_ + j;
    const bool controls = pair_controls_[pair] != 0;
    if (controls_only && !controls) return;
    const int term = pair_term_[pair];
    if (pair_direct_[pair] != 0) {
      // Twelve state coordinates, in order: the pair's derivatives are the term's.
      f(term, g12.data(), h12.data(), 12);
      return;
    }
    const int k = assembly_->TermSize(term);
    // y = C z: node coordinate r from term variable pos (state) or the control block.
    Eigen::Matrix<double, 12, kMaxVars> cm = Eigen::Matrix<double, 12, kMaxVars>::Zero();
    int pos = 0;
    int r = 0;
    for (int node : {i, i + 1, j, j + 1}) {
      for (int c = 0; c < 3; ++c, ++r) {
        const NodeCoord& nc = coords_[3 * node + c];
        if (nc.state >= 0) {
          cm(r, pos++) = 1.0;
        } else if (nc.control >= 0 && cmap != nullptr) {
          cm.block(r, k - nu, 1, nu) = cmap->jac.row(nc.control).head(nu);
        }
      }
    }
    LocalVec ga;
    LocalMat ha;
    ga.noalias() = cm.transpose() * g12;
    if (want_h) {
      const Eigen::Matrix<double, 12, kMaxVars> hc = h12 * cm;
      ha.noalias() = cm.transpose() * hc;
      if (controls && cmap != nullptr) {
        r = 0;
        for (int node : {i, i + 1, j, j + 1}) {
          for (int c = 0; c < 3; ++c, ++r) {
            const NodeCoord& nc = coords_[3 * node + c];
            if (nc.control >= 0)
              ha.block(k - nu, k - nu, nu, nu) += g12[r] * cmap->hess[nc.control].topLeftCorner(nu, nu);
          }
        }
      }
    }
    f(term, ga.data(), ha.data(), kMaxVars);
  });
  if (!feasible) {
    // Touching capsules: no finite derivative. Non-finite outputs make the solvers
    // restore their last good state and report it (model.h).
    const double nan = std::numeric_limits<double>::quiet_NaN();
    f(-1, &nan, &nan, 1);
  }
}

void ContactTerms::AddGradient(const Eigen::Matrix3Xd& nodes, double* g) const {
  ForEach(nodes, nullptr, false, false, [&](int term, const double* lg, const double*, int) {
    if (term < 0) {
      g[0] = lg[0];
      return;
    }
    assembly_->AddGradient(term, lg, g);
  });
}

void ContactTerms::AddHessian(const Eigen::Matrix3Xd& nodes, double* values) const {
  ForEach(nodes, nullptr, true, false, [&](int term, const double* lg, const double* lh, int ld) {
    if (term < 0) {
      values[0] = lg[0];
      return;
    }
    assembly_->AddHessian(term, lh, ld, values);
  });
}

void ContactTerms::AddControlGradient(const Eigen::Matrix3Xd& nodes, const ControlMap& cmap, double* eu) const {
  ForEach(nodes, &cmap, false, true, [&](int term, const double* lg, const double*, int) {
    if (term < 0) {
      eu[0] = lg[0];
      return;
    }
    assembly_->AddControlGradient(term, lg, eu);
  });
}

void ContactTerms::AddMixedHessian(const Eigen::Matrix3Xd& nodes, const ControlMap& cmap, Mat* exu) const {
  ForEach(nodes, &cmap, true, true, [&](int term, const double* lg, const double* lh, int ld) {
    if (term < 0) {
      (*exu)(0, 0) = lg[0];
      return;
    }
    assembly_->AddMixedHessian(term, lh, ld, exu);
  });
}

void ContactTerms::AddControlHessian(const Eigen::Matrix3Xd& nodes, const ControlMap& cmap, Mat* euu) const {
  ForEach(nodes, &cmap, true, true, [&](int term, const double* lg, const double* lh, int ld) {
    if (term < 0) {
      (*euu)(0, 0) = lg[0];
      return;
    }
    assembly_->AddControlHessian(term, lh, ld, euu);
  });
}

}  // namespace snapthread::internal
