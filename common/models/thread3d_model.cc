// The 3D thread of the seed (3.1–3.10, 3.15): N segments, nodes p_0 .. p_N,
//   E = Σ_i E_i,  E_i = γ/2 (l_i - L)² + β/2 (b_i - B)                         (3.7), (3.9)
//   b_i = ((1 - w_{i+1}·w_i) + (1 - w_{i-1}·w_i)) / 2,  w_i = v_i / l_i         (3.6)
// with a missing neighbour's term counting 0 at the two ends. Every joint j (between
// segments j and j+1) appears in b_j and b_{j+1} with weight 1/2 each, so
//   E = Σ_{i=1..N} γ/2 (l_i - L)² + Σ_{j=1..N-1} β/2 (1 - w_j·w_{j+1}) - N β B / 2,
// which is how it is evaluated (B only shifts the energy). p_0 = 0, y_1 = z_1 = 0 (the
// clamp), p_N = (X, Y, Z) = u. State x = [x_1, x_2, y_2, z_2, ..., z_{N-1}] (3N - 5).
//
// Grip direction (params.grip_direction): u = (X, Y, Z, dx, dy, dz) and the held last
// segment points along d: p_{N-1} = p_N - s d/|d| with the scalar s a state variable
// replacing node N-1's three coordinates (3N - 7 states, s last). Terms that touch node
// N-1 are differentiated in node coordinates as usual and then carried to (s, P, d)
// by the chain rule, including the curvature of p_{N-1}(s, d).
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "models/chain_band_terms.h"
#include "models/chain_model.h"
#include "models/chain_terms.h"
#include "models/contact_capability.h"
#include "models/contact_terms.h"
#include "models/registry.h"
#include "models/symmetry_capability.h"

namespace snapthread {
namespace {

using internal::BendTerm;
using internal::ChainModel;
using internal::HessianAssembly;
using internal::StretchTerm;
using V3 = Eigen::Vector3d;

constexpr char kName[] = "thread3d";
constexpr int kMaxVars = HessianAssembly::kMaxTermVars;
using LocalVec = Eigen::Matrix<double, kMaxVars, 1>;
using LocalMat = Eigen::Matrix<double, kMaxVars, kMaxVars>;

// State and control counts: 3N - 5 states and (X, Y, Z), or with a grip 3N - 7 states
// (node N-1's three coordinates become s) and (X, Y, Z, dx, dy, dz).
int NumStatesFor(const ModelParams& p) {
  return p.Bool("grip_direction") ? 3 * p.Integer("n") - 7 : 3 * p.Integer("n") - 5;
}
int NumControlsFor(const ModelParams& p) { return p.Bool("grip_direction") ? 6 : 3; }

class Thread3dModel final : public ChainModel<Thread3dModel>, public ContactCapability, public SymmetryCapability {
 public:
  explicit Thread3dModel(const ModelParams& params)
      : ChainModel(params, NumStatesFor(params), NumControlsFor(params)),
        rest_(params.Number("segment_length")),
        half_beta_(0.5 * params.Number("bending")),
        half_gamma_(0.5 * params.Number("stretching")),
        energy_shift_(-n_ * params.Number("bending") * params.Number("reference_bend") / 2.0),
        grip_(params.Bool("grip_direction")),
        contact_params_(internal::ReadContactParams(params)) {
    AddChainTerms();
    segments_.resize(n_ + 1);
  }

  std::string_view Name() const override { return kName; }
  int SpatialDimension() const override { return 3; }
  // Self-contact only where the scene enables it; the roll always.
  const ContactCapability* contact() const override { return contact_.enabled() ? this : nullptr; }
  const SymmetryCapability* symmetry() const override { return this; }

  // (3.7), (3.9) as the sums above: Σ γ/2 (l_i - L)² + Σ β/2 (1 - w_j·w_{j+1}) - N β B / 2.
  double Energy(const Vec& x, const Vec& u) const override {
    const double e = ChainEnergy<3>(x, u, energy_shift_, half_beta_, half_gamma_, rest_);
    return contact_.enabled() ? e + contact_.Energy(ContactNodes(x, u)) : e;
  }

  // Nodes evenly spaced on the chord from 0 to p_N, plus a bump 1e-3 L sin(π i / N) in a
  // fixed normal direction (the part of +y orthogonal to the chord; +z if the chord is
  // along y). Why: the straight compressed thread is an equilibrium by symmetry that
  // Newton never leaves; the bump picks a buckling side deterministically. The clamp
  // y_1 = z_1 = 0 is re-imposed; with a grip s = |chord| / N (one even segment).
  Vec InitialState(const Vec& u) const override {
    const V3 chord = u.head<3>();
    const double length = chord.norm();
    const V3 along = length > 1e-12 * rest_ ? V3(chord / length) : V3::UnitX();
    V3 normal = V3::UnitY() - along.y() * along;
    if (normal.norm() < 1e-3) normal = V3::UnitZ() - along.z() * along;
    normal.normalize();
    Vec x(nx_);
    const int last_free = grip_ ? n_ - 2 : n_ - 1;
    for (int i = 1; i <= last_free; ++i) {
      const V3 p = (static_cast<double>(i) / n_) * chord +
                   (1e-3 * rest_ * std::sin(std::numbers::pi * i / n_)) * normal;
      if (i == 1) {
        x[0] = p.x();
      } else {
        x.segment<3>(1 + 3 * (i - 2)) = p;
      }
    }
    if (grip_) x[nx_ - 1] = length / n_;
    return x;
  }

  // E, E_x and E_xx in band storage in one pass, as ChainModel's (the same terms in the
  // same order, each term's derivatives by the same operations, so the same bits as
  // Energy(), Gradient() and Hessian(); direct_assembly_test), faster: each segment's
  // length and direction are computed once instead of in three terms (a stretching term
  // and two bending terms: the square roots and divisions were most of BendTerm's time),
  // and a term away from the clamp and the grasp, whose variables are consecutive states,
  // writes the lower triangle of its blocks straight into the band, without the full
  // local Hessian. The few terms at the ends, a grip and self-contact take ChainModel's path.
  bool EnergyGradientAndBandHessian(const Vec& x, const Vec& u, Vec* g, double* band, int bandwidth,
                                    double* energy) const override;

  void NodePositions(const Vec& x, const Vec& u, Eigen::Matrix3Xd* nodes) const override {
    if (nodes->cols() != n_ + 1) nodes->resize(3, n_ + 1);
    for (int i = 0; i <= n_; ++i) nodes->col(i) = Node(i, x, u);
  }
  double Probe(const Vec& x, const Vec& u) const override { return Node(n_ / 2, x, u).y(); }
  // Clamped–pinned Euler load with EI = (β/2) L (see chain_model.h).
  double ForceScale() const override { return EulerLoad(n_, rest_, half_beta_); }

  // The roll: rotation of the free nodes p_2 .. p_{N-1} about the clamp–grasp axis (the
  // line through p_0 = 0 and the grasp), node 1 (x_1 only) and a grip's s unchanged. E
  // is invariant when the grasp (and a grip direction) lies on the clamp axis, where
  // the two axes coincide; near it the roll is nearly free. About the clamp axis instead
  // the grasp would not be on the axis, and rolling half a turn would stretch the last
  // segment by twice the grasp's offset: an orbit far from the near-symmetric one.
  int NumSymmetries() const override { return 1; }
  void SymmetryGenerator(int /*k*/, const Vec& x, const Vec& u, Vec* g) const override {
    g->setZero(x.size());
    const V3 axis = RollAxis(u);
    for (int i = 2; i <= LastFreeNode(); ++i) {
      const int o = 1 + 3 * (i - 2);
      g->segment<3>(o) = axis.cross(V3(x.segment<3>(o)));
    }
  }
  void ApplySymmetry(int /*k*/, double t, const Vec& x, const Vec& u, Vec* y) const override {
    *y = x;
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(t, RollAxis(u)).toRotationMatrix();
    for (int i = 2; i <= LastFreeNode(); ++i) {
      const int o = 1 + 3 * (i - 2);
      y->segment<3>(o) = rotation * V3(x.segment<3>(o));
    }
  }

 private:
  friend class ChainModel<Thread3dModel>;
  struct Term {
    bool bend = false;
    int first_node = 0;
    // Grip terms only (they touch node N-1 = p_N - s d/|d|): which local node that is,
    // and where each variable sits in the term's assembly variable list.
    bool grip = false;
    int grip_local = -1;
    std::array<int, 9> coord_pos{};  // coordinate 3a+k of another local node, or -1
    std::array<int, 7> grip_pos{};   // s, X, Y, Z, dx, dy, dz
  };

  // Generalised index of coordinate k of node i (-1 if fixed). Not for the grip node.
  int NodeVar(int i, int k) const {
    if (i == 0) return -1;
    if (i == 1) return k == 0 ? 0 : -1;
    if (i == n_) return nx_ + k;
    return 1 + 3 * (i - 2) + k;
  }
  bool IsGripNode(int i) const { return grip_ && i == n_ - 1; }
  // The unit clamp–grasp direction (the clamp axis +x for a grasp at the clamp).
  V3 RollAxis(const Vec& u) const {
    const V3 p = u.head<3>();
    const double length = p.norm();
    return length > 1e-12 * rest_ ? V3(p / length) : V3::UnitX();
  }
  // The last node whose three coordinates are state variables.
  int LastFreeNode() const { return grip_ ? n_ - 2 : n_ - 1; }
  V3 Node(int i, const Vec& x, const Vec& u) const {
    if (i == 0) return V3::Zero();
    if (i == 1 && !IsGripNode(1)) return V3(x[0], 0.0, 0.0);
    if (i == n_) return u.head<3>();
    if (IsGripNode(i)) {
      const V3 d = u.segment<3>(3);
      return u.head<3>() - (x[nx_ - 1] / d.norm()) * d;
    }
    return x.segment<3>(1 + 3 * (i - 2));
  }

  void AddTerm(bool bend, int first_node) {
    Term term;
    term.bend = bend;
    term.first_node = first_node;
    const int nodes = bend ? 3 : 2;
    for (int a = 0; a < nodes; ++a) {
      if (IsGripNode(first_node + a)) term.grip_local = a;
    }
    term.grip = term.grip_local >= 0;
    int vars[kMaxVars];
    int count = 0;
    if (!term.grip) {
      for (int a = 0; a < nodes; ++a) {
        for (int k = 0; k < 3; ++k) vars[count++] = NodeVar(first_node + a, k);
      }
    } else {
      // Unique variable list: the other nodes' free coordinates, then s, P, d.
      auto position = [&](int var) {
        for (int m = 0; m < count; ++m) {
          if (vars[m] == var) return m;
        }
        vars[count] = var;
        return count++;
      };
      term.coord_pos.fill(-1);
      for (int a = 0; a < nodes; ++a) {
        if (a == term.grip_local) continue;
        for (int k = 0; k < 3; ++k) {
          const int var = NodeVar(first_node + a, k);
          if (var >= 0) term.coord_pos[3 * a + k] = position(var);
        }
      }
      term.grip_pos[0] = position(nx_ - 1);
      for (int k = 0; k < 6; ++k) term.grip_pos[1 + k] = position(nx_ + k);
    }
    assembly_.AddTerm(vars, count);
    terms_.push_back(term);
  }

  // Local()'s chain rule for a term at the grip: from the term's node coordinates
  // (lg, lh) to its assembly variables (gg, hh), through the grip's node p_{N-1}.
  // lh: null unless want_h.
  void GripChainRule(int t, const Vec& x, const Vec& u, bool want_h, const Eigen::Matrix<double, 9, 1>& lg,
                     const Eigen::Matrix<double, 9, 9>* lh, LocalVec* gg, LocalMat* hh) const {
    // Chain rule to the term's variables through p_{N-1} = P - s d̂, d̂ = d/ρ, ρ = |d|.
    // Its Jacobian w.r.t. g = (s, X, Y, Z, dx, dy, dz) is A = [-d̂ | I | -s Q/ρ] with
    // Q = I - d̂ d̂^T; the other nodes' coordinates map one-to-one. So (G = grip rows)
    //   E_g = A^T e_G,  E_rg = (H_rG A),  E_gg = A^T H_GG A + curvature, where
    //   Σ_k e_k ∂²p_k/∂s∂d_j   = -(Q e)_j / ρ,
    //   Σ_k e_k ∂²p_k/∂d_i∂d_j = s [e_i d̂_j + d̂_i e_j + (e·d̂)(δ_ij - 3 d̂_i d̂_j)] / ρ².
    // Variables shared with node N (X, Y, Z) simply accumulate.
    const V3 d = u.segment<3>(3);
    const double rho = d.norm();
    const V3 dh = d / rho;
    const double s = x[nx_ - 1];
    Eigen::Matrix3d q = -dh * dh.transpose();
    q.diagonal().array() += 1.0;
    Eigen::Matrix<double, 3, 7> jac_grip;
    jac_grip.col(0) = -dh;
    jac_grip.middleCols<3>(1).setIdentity();
    jac_grip.rightCols<3>() = (-s / rho) * q;
    const Term& term = terms_[t];
    const int nodes = term.bend ? 3 : 2;
    const int g0 = 3 * term.grip_local;
    const int k = assembly_.TermSize(t);
    const V3 eg = lg.segment<3>(g0);
    gg->head(k).setZero();
    for (int r = 0; r < 3 * nodes; ++r) {
      if (r < g0 || r >= g0 + 3) {
        if (term.coord_pos[r] >= 0) (*gg)[term.coord_pos[r]] += lg[r];
      }
    }
    const Eigen::Matrix<double, 7, 1> ag = jac_grip.transpose() * eg;
    for (int m = 0; m < 7; ++m) (*gg)[term.grip_pos[m]] += ag[m];
    if (want_h) {
      hh->topLeftCorner(k, k).setZero();
      const Eigen::Matrix<double, 9, 7> b = lh->middleCols<3>(g0) * jac_grip;
      for (int c = 0; c < 3 * nodes; ++c) {
        if (c >= g0 && c < g0 + 3) continue;
        const int pc = term.coord_pos[c];
        if (pc < 0) continue;
        for (int r = 0; r < 3 * nodes; ++r) {
          if (r >= g0 && r < g0 + 3) continue;
          if (term.coord_pos[r] >= 0) (*hh)(term.coord_pos[r], pc) += (*lh)(r, c);
        }
        for (int m = 0; m < 7; ++m) {
          (*hh)(pc, term.grip_pos[m]) += b(c, m);
          (*hh)(term.grip_pos[m], pc) += b(c, m);
        }
      }
      Eigen::Matrix<double, 7, 7> gg_block = jac_grip.transpose() * b.middleRows<3>(g0);
      const V3 qe = q * eg / rho;
      const double ed = eg.dot(dh);
      const double cs = s / (rho * rho);
      for (int j = 0; j < 3; ++j) {
        gg_block(0, 4 + j) -= qe[j];
        gg_block(4 + j, 0) -= qe[j];
        for (int i = 0; i < 3; ++i) {
          gg_block(4 + i, 4 + j) +=
              cs * (eg[i] * dh[j] + dh[i] * eg[j] + ed * ((i == j ? 1.0 : 0.0) - 3.0 * dh[i] * dh[j]));
        }
      }
      for (int m2 = 0; m2 < 7; ++m2) {
        for (int m = 0; m < 7; ++m) (*hh)(term.grip_pos[m], term.grip_pos[m2]) += gg_block(m, m2);
      }
    }
  }

  // Calls f(local gradient, local Hessian (valid if want_h), leading dimension) for
  // term t, in the term's assembly variables; returns the term's energy (the value
  // ChainEnergy adds for it).
  template <class F>
  double Local(int t, const Vec& x, const Vec& u, bool want_h, F&& f) const {
    const Term& term = terms_[t];
    const int a = term.first_node;
    Eigen::Matrix<double, 9, 1> lg;
    Eigen::Matrix<double, 9, 9> lh;
    double energy;
    if (term.bend) {
      energy = BendTerm<3>(Node(a, x, u), Node(a + 1, x, u), Node(a + 2, x, u), half_beta_, &lg,
                  want_h ? &lh : nullptr);
    } else {
      Eigen::Matrix<double, 6, 1> g6;
      Eigen::Matrix<double, 6, 6> h6;
      energy = StretchTerm<3>(Node(a, x, u), Node(a + 1, x, u), half_gamma_, rest_, &g6,
                              want_h ? &h6 : nullptr);
      if (!term.grip) {
        f(g6.data(), h6.data(), 6);
        return energy;
      }
      lg.head<6>() = g6;
      lg.tail<3>().setZero();
      if (want_h) {
        lh.setZero();
        lh.topLeftCorner<6, 6>() = h6;
      }
    }
    if (!term.grip) {
      f(lg.data(), lh.data(), 9);
      return energy;
    }
    LocalVec gg;
    LocalMat hh;
    GripChainRule(t, x, u, want_h, lg, want_h ? &lh : nullptr, &gg, &hh);
    f(gg.data(), hh.data(), kMaxVars);
    return energy;
  }

  const double rest_;        // L
  const double half_beta_;   // β/2
  const double half_gamma_;  // γ/2
  const double energy_shift_;  // -N β B / 2
  const bool grip_;
  std::vector<Term> terms_;
  // EnergyGradientAndBandHessian's segment cache (segments 1 .. N; sized once). Scratch,
  // like the contact scratch below: one evaluation at a time per model instance.
  struct Segment {
    V3 w;        // v / l
    double l;    // |v|, v = p_s - p_{s-1}
    double inv;  // 1 / l
  };
  mutable std::vector<Segment> segments_;
  // The first state of a term whose variables are the consecutive states v0, v0 + 1, ...
  // (its nodes are all free: not node 0 or 1, not the grasp, no grip), else -1.
  int ContiguousStart(const Term& term) const {
    const int last = term.first_node + (term.bend ? 2 : 1);
    return (!grip_ && term.first_node >= 2 && last <= n_ - 1) ? NodeVar(term.first_node, 0) : -1;
  }

  // Self-contact (models/contact_terms.h): p_0 and y_1, z_1 fixed, x_1 and
  // p_2 .. p_{N-1} state variables, p_N = u. Not with a grip (the scene check says so).
  void RegisterContact() {
    contact_.Register(contact_params_, n_, rest_,
                      [&](int i, int k) {
                        internal::NodeCoord nc;
                        if (i == n_) nc.control = k;
                        else nc.state = NodeVar(i, k);
                        return nc;
                      },
                      &assembly_);
    if (contact_.enabled()) {
      for (int k = 0; k < 3; ++k) controls_.jac(k, k) = 1.0;
      for (auto& h : controls_.hess) h.setZero();
    }
  }
  // ChainModel's hooks for the fused energy: what Energy() adds to the chain's terms.
  double EnergyShift() const { return energy_shift_; }
  double ContactEnergy(const Vec& x, const Vec& u) const {
    return contact_.enabled() ? contact_.Energy(ContactNodes(x, u)) : 0.0;
  }
  const Eigen::Matrix3Xd& ContactNodes(const Vec& x, const Vec& u) const {
    NodePositions(x, u, &contact_nodes_);
    return contact_nodes_;
  }
  void AddContactGradient(const Vec& x, const Vec& u, Vec* g) const {
    if (contact_.enabled()) contact_.AddGradient(ContactNodes(x, u), g->data());
  }
  void CoverContacts(const Vec& x, const Vec& u) const {
    if (contact_.enabled()) contact_.CoverActive(ContactNodes(x, u));
  }
  void AddContactHessian(const Vec& x, const Vec& u, double* values) const {
    if (contact_.enabled()) contact_.AddHessian(ContactNodes(x, u), values);
  }
  void AddContactControlGradient(const Vec& x, const Vec& u, Vec* eu) const {
    if (contact_.enabled()) contact_.AddControlGradient(ContactNodes(x, u), controls_, eu->data());
  }
  void AddContactMixedHessian(const Vec& x, const Vec& u, Mat* exu) const {
    if (contact_.enabled()) contact_.AddMixedHessian(ContactNodes(x, u), controls_, exu);
  }
  void AddContactControlHessian(const Vec& x, const Vec& u, Mat* euu) const {
    if (contact_.enabled()) contact_.AddControlHessian(ContactNodes(x, u), controls_, euu);
  }

 public:
  // ContactCapability (contact() offers it only with contact enabled).
  double MaxStepFraction(const Vec& x, const Vec& dx, const Vec& u) const override {
    contact_trial_ = x + dx;
    return MaxMotionFraction(x, u, contact_trial_, u);
  }
  double MaxMotionFraction(const Vec& x0, const Vec& u0, const Vec& x1, const Vec& u1) const override {
    NodePositions(x0, u0, &contact_nodes_);
    NodePositions(x1, u1, &contact_to_);
    return contact_.self().MaxStepFraction(contact_nodes_, contact_to_);
  }
  std::vector<contact::ContactPoint> ActiveContacts(const Vec& x, const Vec& u) const override {
    Eigen::Matrix3Xd nodes;
    NodePositions(x, u, &nodes);
    return contact_.self().ActivePairs(nodes);
  }

 private:
  const contact::ContactParams contact_params_;
  internal::ContactTerms contact_;
  internal::ControlMap controls_;
  mutable Eigen::Matrix3Xd contact_nodes_, contact_to_;
  mutable Vec contact_trial_;
};

bool Thread3dModel::EnergyGradientAndBandHessian(const Vec& x, const Vec& u, Vec* g, double* band, int bandwidth,
                                                 double* energy) const {
  if (grip_ || contact_.enabled()) return ChainModel::EnergyGradientAndBandHessian(x, u, g, band, bandwidth, energy);
  if (bandwidth != assembly_.Bandwidth()) return false;
  if (g->size() != nx_) g->resize(nx_);
  g->setZero();
  double* gd = g->data();
  std::fill(band, band + static_cast<std::ptrdiff_t>(nx_) * (bandwidth + 1), 0.0);
  // Segment s from p_{s-1} to p_s, as StretchTerm and BendTerm compute it (v, |v|, 1/|v|, v/|v|).
  for (int s = 1; s <= n_; ++s) {
    const V3 v = Node(s, x, u) - Node(s - 1, x, u);
    Segment& seg = segments_[s];
    seg.l = v.norm();
    seg.inv = 1.0 / seg.l;
    seg.w = v * seg.inv;
  }
  double e = energy_shift_;
  for (int t = 0; t < chain_terms_; ++t) {
    const Term& term = terms_[t];
    const int v0 = ContiguousStart(term);
    if (v0 < 0) {
      e += Local(t, x, u, /*want_h=*/true, [&](const double* lg, const double* lh, int lhd) {
        assembly_.AddGradient(t, lg, gd);
        assembly_.AddBandHessian(t, lh, lhd, band);
      });
    } else if (!term.bend) {
      const Segment& sg = segments_[term.first_node + 1];
      e += internal::StretchIntoBand(sg.w.data(), sg.l, sg.inv, half_gamma_, rest_, v0, gd, band, bandwidth);
    } else {
      const Segment& s1 = segments_[term.first_node + 1];
      const Segment& s2 = segments_[term.first_node + 2];
      e += internal::BendIntoBand(s1.w.data(), s1.inv, s2.w.data(), s2.inv, s1.w.dot(s2.w), half_beta_, v0, gd,
                                  band, bandwidth);
    }
  }
  *energy = e;
  return true;
}

}  // namespace

ModelRegistration Thread3dRegistration() {
  ModelRegistration r;
  r.name = kName;
  r.doc = "3D elastic thread of N segments, clamped at the origin, held at its end (3.1-3.10, 3.15)";
  r.params = internal::ChainParamSpecs("beta in beta/2 (b_i - B) (3.9)", "gamma in gamma/2 (l_i - L)^2 (3.7)");
  r.params.push_back({.name = "reference_bend", .default_value = 0.0, .doc = "B (3.9); shifts the energy only"});
  r.params.push_back({.name = "grip_direction", .kind = ParamKind::kBool, .default_value = 0.0,
                      .doc = "the grip also holds the last segment's direction: u = (X, Y, Z, dx, dy, dz)"});
  r.params.push_back({.name = "radius", .default_value = 0.0, .min = 0.0, .units = "model length",
                      .doc = "capsule radius of self-contact (0: the centrelines only must not cross)"});
  for (ParamSpec& spec : internal::ContactParamSpecs()) r.params.push_back(std::move(spec));
  // A grip needs N >= 3: node N-1 must not be the clamped node 1.
  r.check = [](const ModelParams& p, std::string* error) {
    if (p.Bool("grip_direction") && p.Bool("contact")) {
      if (error) *error = "params.contact: not available with grip_direction (the gripped node is not yet carried)";
      return false;
    }
    if (!p.Bool("grip_direction") || p.Integer("n") >= 3) return true;
    if (error) *error = "params.n: expected an integer >= 3, got " + std::to_string(p.Integer("n"));
    return false;
  };
  r.factory = [](const ModelParams& p) -> std::unique_ptr<Model> { return std::make_unique<Thread3dModel>(p); };
  r.capabilities.grasp_layout = [](const ModelParams& p) {
    return GraspLayout{.spatial_dimension = 3, .grip_direction = p.Bool("grip_direction")};
  };
  r.capabilities.chain = ChainSpec{.per_length = {"bending", "stretching"}};
  return r;
}

}  // namespace snapthread
