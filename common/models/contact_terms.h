// Self-contact as terms of a chain model (issue 15): the scene parameters of contact,
// and the barrier pairs (contact/self_contact.h) registered in the model's
// HessianAssembly and carried from node coordinates to the model's variables.
//
// A node coordinate is a state variable, a function of the controls only (a grasped
// node: Jacobian row and Hessian over u, filled in by the model at each evaluation), or
// fixed (the clamp). Every pair that may ever touch is a term, so the E_xx pattern is
// fixed at construction as model.h requires; it is dense among the nodes that can meet.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "contact/self_contact.h"
#include "models/hessian_assembly.h"
#include "models/params.h"

namespace snapthread::internal {

// Scene parameters: contact (bool), contact_distance (d̂), contact_stiffness (κ);
// `radius` is the model's own.
std::vector<ParamSpec> ContactParamSpecs();
contact::ContactParams ReadContactParams(const ModelParams& params);

// Where a node coordinate comes from.
struct NodeCoord {
  int state = -1;    // state index, or -1
  int control = -1;  // row of ControlMap (0..11), or -1; neither: fixed
};

// The controlled node coordinates as functions of u: rows of the Jacobian over u and,
// per row, its Hessian over u. Up to 12 rows (a free rod's two grasped edges, four
// nodes) over up to 12 controls (two full poses); a model fills the leading rows and its
// NumControls() columns.
struct ControlMap {
  static constexpr int kRows = 12;
  static constexpr int kControls = 12;
  Eigen::Matrix<double, kRows, kControls> jac = Eigen::Matrix<double, kRows, kControls>::Zero();
  std::array<Eigen::Matrix<double, kControls, kControls>, kRows> hess{};
};

class ContactTerms {
 public:
  // Registers one assembly term per included pair (before assembly->Finalize()). `code`
  // says where node k's coordinate c comes from. Nothing is registered when disabled.
  void Register(const contact::ContactParams& params, int segments, double rest_length,
                const std::function<NodeCoord(int, int)>& code, HessianAssembly* assembly);

  bool enabled() const { return self_.enabled(); }
  const contact::SelfContact& self() const { return self_; }

  double Energy(const Eigen::Matrix3Xd& nodes) const { return enabled() ? self_.Energy(nodes) : 0.0; }
  // Add the barrier's E_x, E_xx values (pattern of the assembly), E_u, E_xu, E_uu.
  // Infeasible states (touching capsules) make the outputs non-finite.
  void AddGradient(const Eigen::Matrix3Xd& nodes, double* g) const;
  void AddHessian(const Eigen::Matrix3Xd& nodes, double* values) const;
  void AddControlGradient(const Eigen::Matrix3Xd& nodes, const ControlMap& cmap, double* eu) const;
  void AddMixedHessian(const Eigen::Matrix3Xd& nodes, const ControlMap& cmap, Mat* exu) const;
  void AddControlHessian(const Eigen::Matrix3Xd& nodes, const ControlMap& cmap, Mat* euu) const;

 private:
  // A pair term: its 12 endpoint coordinates' state variables, and every control when
  // one of them is grasped (12 + 12 at most).
  static constexpr int kMaxVars = HessianAssembly::kMaxPairTermVars;
  using LocalVec = Eigen::Matrix<double, kMaxVars, 1>;
  using LocalMat = Eigen::Matrix<double, kMaxVars, kMaxVars>;
  // Calls f(term, local gradient, local Hessian, leading dimension) for each active
  // pair, in the term's variables; control-free pairs skipped when `controls_only`.
  // After the pairs, f(-1, NaN, ...) once if some pair touches.
  template <class F>
  void ForEach(const Eigen::Matrix3Xd& nodes, const ControlMap* cmap, bool want_h, bool controls_only,
               F&& f) const;

  contact::SelfContact self_;
  const HessianAssembly* assembly_ = nullptr;
  int segments_ = 0;
  std::vector<NodeCoord> coords_;  // 3 per node
  std::vector<int> pair_term_;     // i * segments + j -> term id
  std::vector<char> pair_controls_;
  // The term's variables are the pair's 12 coordinates in order (all state variables):
  // its local derivatives are the pair's own, no mapping.
  std::vector<char> pair_direct_;
};

}  // namespace snapthread::internal
