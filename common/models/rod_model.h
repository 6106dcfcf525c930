// The discrete elastic rod (Bergou et al. 2008 [DER], 2010 [DVT]):
// n edges, nodes x_0 .. x_n and one material angle θ_j per edge against a time-parallel
// reference frame (rod_frames.h, rod_energy.h; docs/models-rod.md).
//
// Clamp and grasp are full poses. The clamp (position c, rotation R_c) fixes edge 0:
// x_0 = c, x_1 = c + ℓ R_c e_x, material frame (m1, m2) = (R_c e_y, R_c e_z), θ_0 = 0.
// The grasp u = (p, φ) with orientation R(u) = exp([φ]×) R_start fixes edge n-1:
// x_n = p, x_{n-1} = p - ℓ R(u) e_x, m1_{n-1} = R(u) e_y. Body axes: x along the rod,
// y = m1, z = m2.
//
// State x (4n - 11 entries), ordered for a narrow band:
//   [θ_1, x_2, θ_2, x_3, θ_3, ..., x_{n-2}, θ_{n-2}]   (half-bandwidth 10: a vertex couples three nodes)
//
// Controls and torque. E_u = (E_p, E_φ). F = -E_p is the force of the rod on the hand
// (world frame). -E_φ is the torque conjugate to the rotation vector φ; at φ = 0 (and
// whenever φ is parallel to the rotation axis, e.g. a roll about a fixed axis) it is the
// torque of the rod on the hand about the grasp point x_n in world coordinates. In
// general the world torque is τ = -J_l(φ)^{-T} E_φ with the left Jacobian of SO(3),
// J_l(φ) = I + (1 - cos|φ|)/|φ|² [φ]× + (|φ| - sin|φ|)/|φ|³ [φ]×².
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "models/band_assembly_capability.h"
#include "models/contact_capability.h"
#include "models/contact_terms.h"
#include "models/frames_capability.h"
#include "models/grasp_torque_capability.h"
#include "models/hessian_assembly.h"
#include "models/history_capability.h"
#include "models/model.h"
#include "models/rod_energy.h"
#include "models/rod_params.h"

namespace snapthread {

class RodModel final : public Model,
                       public BandAssemblyCapability,
                       public ContactCapability,
                       public FramesCapability,
                       public GraspTorqueCapability,
                       public HistoryCapability {
 public:
  // Throws std::invalid_argument if !params.IsValid().
  explicit RodModel(const RodParams& params);

  // Every capability but symmetries (the clamp and the grasp hold full poses); self-contact
  // only where the params enable it.
  const BandAssemblyCapability* band_assembly() const override { return this; }
  const ContactCapability* contact() const override { return contact_.enabled() ? this : nullptr; }
  const FramesCapability* frames() const override { return this; }
  const GraspTorqueCapability* grasp_torque() const override { return this; }
  HistoryCapability* history() override { return this; }

  std::string_view Name() const override { return "rod"; }
  int NumStates() const override { return nx_; }
  int NumControls() const override { return nu_; }
  int SpatialDimension() const override { return 3; }

  double Energy(const Vec& x, const Vec& u) const override;
  void Gradient(const Vec& x, const Vec& u, Vec* g) const override;
  const SparseMatrix& HessianPattern() const override { return assembly_.Pattern(); }
  int HessianPatternVersion() const override { return assembly_.PatternVersion(); }
  void Hessian(const Vec& x, const Vec& u, SparseMatrix* h) const override;
  // One pass over the terms for both (the same operations as the two, the same bits).
  void GradientAndHessian(const Vec& x, const Vec& u, Vec* g, SparseMatrix* h) const override;
  // One pass for E, E_x and E_xx (Energy()'s sum in its order: the same bits).
  double EnergyGradientAndHessian(const Vec& x, const Vec& u, Vec* g, SparseMatrix* h) const override;
  // The same with E_xx written straight into the band (false with self-contact, whose
  // pairs go through the compressed matrix, or another bandwidth).
  bool EnergyGradientAndBandHessian(const Vec& x, const Vec& u, Vec* g, double* band, int bandwidth,
                                    double* energy) const override;
  void ControlGradient(const Vec& x, const Vec& u, Vec* eu) const override;
  void MixedHessian(const Vec& x, const Vec& u, Mat* exu) const override;
  void ControlHessian(const Vec& x, const Vec& u, Mat* euu) const override;
  // One pass over the terms that touch the grasp for all three (the same bits).
  void ControlDerivatives(const Vec& x, const Vec& u, Vec* eu, Mat* exu, Mat* euu) const override;
  // -dE/dδ for a world rotation exp([δ]×) of the grasp: the torque about x_n (N m)
  // (free_start: of the first grasp, about x_0).
  void GraspTorque(const Vec& x, const Vec& u, Eigen::Vector3d* torque) const override;

  // Nodes evenly spaced on the segment x_1 .. x_{n-1}, twist spread evenly.
  Vec InitialState(const Vec& u) const override;
  void NodePositions(const Vec& x, const Vec& u, Eigen::Matrix3Xd* nodes) const override;
  // The largest distance of any node from the clamp–grasp line (x_0, x_n): 0 while straight.
  double Probe(const Vec& x, const Vec& u) const override;
  // EI / L².
  double ForceScale() const override;
  int HessianBandwidth() const override { return assembly_.Bandwidth(); }
  // Moves the time-parallel reference frames (and the continued reference twists and
  // grasp angle) to the accepted state.
  void AcceptState(const Vec& x, const Vec& u) override;
  // Back to the rest frames (straight along the clamp, no turns at the grasp).
  void ResetHistory() override;
  // Self-contact (rod_contact.cc): a whole step and no pairs without contact.
  double MaxStepFraction(const Vec& x, const Vec& dx, const Vec& u) const override;
  double MaxMotionFraction(const Vec& x0, const Vec& u0, const Vec& x1, const Vec& u1) const override;
  std::vector<contact::ContactPoint> ActiveContacts(const Vec& x, const Vec& u) const override;
  const contact::SelfContact& self_contact() const { return contact_.self(); }

  // Layout, for tests and scene code: the state index of coordinate 0 of node k and of
  // θ_j, or -1 when the clamp or the grasp sets it.
  int NodeIndex(int k) const;
  int ThetaIndex(int j) const;
  // θ_j for every edge (θ_0 = 0, θ_{n-1} from the grasp).
  Vec MaterialAngles(const Vec& x, const Vec& u) const;
  // Material director m1 of edge j.
  Eigen::Vector3d MaterialDirector(const Vec& x, const Vec& u, int j) const;
  // For drawing (rod_shape.cc): m1 of every edge (3 x n) and the twist density of every
  // edge (rad per unit length): the total twist θ_i − θ_{i−1} + m_i of its end vertices
  // [DVT (2)] averaged (edges 0 and n−1 have one interior vertex) over ℓ̄ = ℓ. A straight
  // rod whose held edges are turned by Φ against each other has Φ / ((n − 1) ℓ) on every
  // edge (the twist acts between the held edges' midpoints).
  void MaterialFrames(const Vec& x, const Vec& u, Eigen::Matrix3Xd* d1, Vec* twist_density) const override;
  Vec TwistDensity(const Vec& x, const Vec& u) const;
  const RodParams& params() const { return p_; }

 private:
  static constexpr int kMaxLocal = 11;  // a vertex term: three nodes and two angles
  // u -> x_{n-1}, x_n, θ_{n-1}: values, Jacobian (7 x 6 over (p, φ)) and, for each of the
  // seven coordinates, the Hessian in φ (the map is linear in p).
  struct GraspMap {
    Eigen::Vector3d xn1, xn;
    double theta = 0.0;
    Eigen::Matrix<double, 7, 6> jac;
    std::array<Eigen::Matrix3d, 7> hess_phi;
  };

  // The grasp of edge n-1 and, without a clamp, the one of edge 0 (unused otherwise).
  struct GraspMaps {
    GraspMap end;
    GraspMap start;
  };
  // One energy term (stretching of an edge, or bending and twist at a vertex). Local
  // coordinate codes: >= 0 a state index, -1 fixed by the clamp, -2 - g grasp
  // coordinate g (0..2 x_{n-1}, 3..5 x_n, 6 θ_{n-1}); free_start: -9 - g coordinate g of
  // the grasp of edge 0 (0..2 x_1, 3..5 x_0, 6 θ_0). No term touches both grasps (n ≥ 5).
  struct Term {
    bool vertex = false;
    int index = 0;  // edge (stretch) or vertex
    int nloc = 0;
    bool grasp = false;
    bool at_start = false;  // the grasp it touches holds edge 0
    std::array<int, kMaxLocal> code{};
    std::array<int, kMaxLocal> pos{};  // grasp terms: assembly position of state coordinates
    // A term whose coordinates are all free states, one block of the state from `first`
    // (a vertex: x_{i-1}, θ_{i-1}, x_i, θ_i, x_{i+1}; an edge: x_j, θ_j, x_{j+1} with θ_j
    // not touched): its gradient and lower band are written straight from the term's own
    // derivatives (AddInteriorTerm), -1 otherwise.
    int first = -1;
  };
  void BuildTerms();
  // Self-contact (rod_contact.cc): pair terms registered after the elastic ones, node
  // positions into contact_nodes_, and the grasped nodes' map for E_u, E_xu, E_uu
  // (one grasp's two nodes, or both grasps' four without a clamp).
  void RegisterContact();
  const Eigen::Matrix3Xd& ContactNodes(const Vec& x, const GraspMaps& gm) const;
  internal::ControlMap ContactControls(const GraspMaps& gm) const;
  // rod_grasp.cc. The values (nodes, angle) do not depend on `derivatives`: the same
  // operations, the same bits.
  GraspMaps Grasp(const Vec& u, bool derivatives, bool world_rotation = false) const;
  // Grasp(u, true), kept for the last u until the lagged data move (AcceptState,
  // ResetHistory): every evaluation of one update asks for the same u.
  const GraspMaps& GraspDerivatives(const Vec& u) const;
  // The map of one grasp: the one of edge n-1 (at_start false) or of edge 0.
  GraspMap OneGrasp(const Vec& u, bool at_start, bool derivatives, bool world_rotation) const;
  Eigen::Vector3d Node(int k, const Vec& x, const GraspMaps& gm) const;
  double Theta(int j, const Vec& x, const GraspMaps& gm) const;
  // Each edge's frame once per evaluation (both of its vertices use it) into edges_: every
  // edge, or (control_terms_only) those of the terms that touch the grasp. Drops
  // frames_key_ unless (x, u) is its state.
  void PrepareEdges(const Vec& x, const Vec& u, const GraspMaps& gm, bool want_h, bool control_terms_only) const;
  // The stretching term of edge j from edges_ (g, h may be null).
  double StretchEnergy(int j, Eigen::Matrix<double, 6, 1>* g, Eigen::Matrix<double, 6, 6>* h) const;
  // Calls f(local gradient, local Hessian, leading dimension) for term t in its
  // assembly variables, with its edges in edges_ (PrepareEdges); returns the term's energy.
  template <class F>
  double Local(int t, const GraspMaps& gm, bool want_h, F&& f) const;
  // Local()'s steps: the term's energy and its derivatives in its own coordinates y (the
  // nodes and angles it touches; g and h may be uninitialised past the term's size), and,
  // for a term that touches a grasp, the chain rule through the grasp map to its
  // assembly variables (states, then the 6 controls).
  using LocalGradient = Eigen::Matrix<double, kMaxLocal, 1>;
  using LocalHessian = Eigen::Matrix<double, kMaxLocal, kMaxLocal>;
  using TermGradient = Eigen::Matrix<double, internal::HessianAssembly::kMaxTermVars, 1>;
  using TermHessian =
      Eigen::Matrix<double, internal::HessianAssembly::kMaxTermVars, internal::HessianAssembly::kMaxTermVars>;
  double TermDerivatives(const Term& term, bool want_h, LocalGradient* gy, LocalHessian* hy) const;
  void GraspChainRule(int t, const GraspMaps& gms, bool want_h, const LocalGradient& gy, const LocalHessian& hy,
                      TermGradient* ga, TermHessian* ha) const;
  // An interior term (Term::first >= 0) straight into g and, when band is not null, the
  // lower band of half-bandwidth b: the values Local() and the assembly give, the same bits.
  double AddInteriorTerm(const Term& term, double* g, double* band, int b) const;
  // Its two kinds: an edge's stretching, a vertex's bending and twist.
  double AddInteriorEdge(const Term& term, double* g, double* band, int b) const;
  double AddInteriorVertex(const Term& term, double* g, double* band, int b) const;

  RodParams p_;
  int n_;
  int nx_;
  int nu_ = 6;  // 12 with free_start
  double rest_;  // ℓ
  rod::VertexStiffness stiffness_;
  internal::HessianAssembly assembly_;
  std::vector<Term> terms_;  // the elastic terms (assembly terms 0 .. size-1)
  std::vector<int> control_terms_;
  internal::ContactTerms contact_;
  mutable Eigen::Matrix3Xd contact_nodes_, contact_to_;
  mutable Vec contact_trial_;
  // Evaluation scratch (sized at construction; one model is evaluated by one thread at a
  // time, as the tracker does): the edge frames and the cached grasp maps.
  mutable std::vector<rod::EdgeFrame> edges_;
  mutable GraspMaps grasp_cache_;
  mutable Vec grasp_cache_u_;
  mutable bool grasp_cache_valid_ = false;
  // The last state whose energy was evaluated (Energy, or a fused pass), and the band of the
  // last EnergyGradientAndBandHessian with its state: a solver asks for E again at a state
  // it has evaluated, and for the compressed E_xx at the state of a band it factorised
  // (rod_evaluate.cc). Invalidated with the grasp maps (the lagged data moved).
  struct StateKey {
    Vec x, u;
    bool valid = false;
    bool Matches(const Vec& x1, const Vec& u1) const;
    void Set(const Vec& x1, const Vec& u1);
  };
  mutable StateKey energy_key_, band_key_;
  // The state of the last pass over every term (Energy, Gradient, a Hessian or a fused
  // pass): edges_ holds its frames and twist_cache_ each vertex's reference twist, which
  // AcceptState takes instead of computing them again.
  mutable StateKey frames_key_;
  mutable std::vector<double> twist_cache_;

  mutable double energy_cache_ = 0.0;
  mutable std::vector<double> band_cache_;
  void InvalidateCaches();
  // Lagged data (AcceptState): per edge the frame source, per vertex the reference twist,
  // and the grasp's material angle, each the value at the last accepted state.
  std::vector<rod::FrameSource> sources_;
  std::vector<double> twist_near_;
  double grasp_theta_near_ = 0.0;
  double start_theta_near_ = 0.0;  // free_start: the same for the grasp of edge 0
};

}  // namespace snapthread
