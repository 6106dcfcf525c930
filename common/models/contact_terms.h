// Self-contact as terms of a chain model: the scene parameters of contact,
// and the barrier pairs (contact/self_contact.h) registered in the model's
// HessianAssembly and carried from node coordinates to the model's variables.
//
// A node coordinate is a state variable, a function of the controls only (a grasped
// node: Jacobian row and Hessian over u, filled in by the model at each evaluation), or
// fixed (the clamp).
//
// The E_xx pattern: the chain's own band plus the blocks of the pairs
// near contact — the "set", pairs whose centrelines lie within the activation distance
// 2r + d̂ plus a margin (kMargin of it) — as dynamic terms of the assembly
// (hessian_assembly.h). Before E_xx is written at a state, CoverActive() checks that
// every pair active there is in the set; only when one is not is the set rebuilt (broad
// phase, O(n + pairs near contact)) and the pattern changed, which the solvers see by
// its version and answer with a new symbolic analysis. Pairs outside the set contribute
// nothing to E_xx (inactive: the barrier and its derivatives vanish), so the matrix is
// the exact Hessian and its inertia exact. E_x, E_u, E_xu and E_uu need no pattern.
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
  // Before assembly->Finalize(): `code` says where node k's coordinate c comes from; the
  // assembly takes dynamic terms (the set starts empty). Nothing happens when disabled.
  void Register(const contact::ContactParams& params, int segments, double rest_length,
                const std::function<NodeCoord(int, int)>& code, HessianAssembly* assembly);

  // Before a model writes E_xx at these node positions (ahead of assembly.Values()):
  // makes the pattern cover every pair active here, rebuilding the set (and the
  // pattern: its version moves) when one is missing. Returns true if it rebuilt.
  bool CoverActive(const Eigen::Matrix3Xd& nodes) const;
  // Pairs in the set, and how many times it was rebuilt (benchmarks, tests).
  int SetSize() const { return static_cast<int>(set_.size()); }
  int Rebuilds() const { return rebuilds_; }
  // The set's reach beyond the activation distance, as a multiple of it. Measured on the
  // knot path (docs/benchmarks.md): a wide margin re-analyses seldom but factorises the
  // blocks of many idle pairs each step (margin 1: median 1.34 ms an update at n = 100);
  // 0 to 0.2 were alike (0.67 to 0.79 ms), a re-analysis every few updates.
  static constexpr double kMargin = 0.1;

  bool enabled() const { return self_.enabled(); }
  const contact::SelfContact& self() const { return self_; }

  double Energy(const Eigen::Matrix3Xd& nodes) const { return enabled() ? self_.Energy(nodes) : 0.0; }
  // Add the barrier's E_x, E_xx values (pattern of the assembly, after CoverActive() at
  // these nodes), E_u, E_xu, E_uu. Infeasible states (touching capsules) make the
  // outputs non-finite; so does an active pair the pattern lacks (CoverActive() not called).
  void AddGradient(const Eigen::Matrix3Xd& nodes, double* g) const;
  void AddHessian(const Eigen::Matrix3Xd& nodes, double* values) const;
  void AddControlGradient(const Eigen::Matrix3Xd& nodes, const ControlMap& cmap, double* eu) const;
  void AddMixedHessian(const Eigen::Matrix3Xd& nodes, const ControlMap& cmap, Mat* exu) const;
  void AddControlHessian(const Eigen::Matrix3Xd& nodes, const ControlMap& cmap, Mat* euu) const;

 private:
  // Calls f(i, j, g12, h12) for each active pair (its derivatives in the 12 coordinates
  // of its nodes; control-free pairs skipped when `controls_only`), then f(-1, -1, NaN
  // gradient, ...) once if some pair touches.
  template <class F>
  void ForEach(const Eigen::Matrix3Xd& nodes, bool want_h, bool controls_only, F&& f) const;
  const NodeCoord& Coord(int node, int c) const { return coords_[3 * node + c]; }
  // The 12 coordinates of pair (i, j): node i, i + 1, j, j + 1, three each.
  int Node(int i, int j, int r) const { return (r < 6 ? i : j - 2) + r / 3; }

  contact::SelfContact self_;
  HessianAssembly* assembly_ = nullptr;
  int segments_ = 0;
  std::vector<NodeCoord> coords_;  // 3 per node
  std::vector<char> node_controls_;  // a coordinate of node k is a control's
  // The set: pairs (sorted) and, for each pair i * segments + j, its dynamic term (its
  // state coordinates, in the pair's order) or -1. Rebuilt by CoverActive().
  mutable std::vector<std::pair<int, int>> set_;
  mutable std::vector<int> pair_term_;
  mutable std::vector<int> term_vars_, term_begin_;
  mutable std::vector<std::pair<int, int>> scratch_pairs_;
  mutable int rebuilds_ = 0;
};

}  // namespace snapthread::internal
