#include "models/rod_model.h"

#include "models/registry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace snapthread {

using rod::FrameSource;
using rod::Jet;
using rod::JetVec;
using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;
constexpr int kMaxVars = internal::HessianAssembly::kMaxTermVars;

// The grasp coordinate g of a local code (RodModel::Term): -2 - g, or -9 - g for the grasp
// of edge 0.
int GraspCoordinate(int code) { return code <= -9 ? -9 - code : -2 - code; }

bool RodParams::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error != nullptr) *error = "rod: " + why;
    return false;
  };
  if (n < 3) return fail("n must be at least 3 (the clamp and the grasp hold one edge each)");
  if (free_start && n < 5) return fail("n must be at least 5 without a clamp (two grasps)");
  if (!(length > 0.0) || !std::isfinite(length)) return fail("length must be positive");
  const double stiffnesses[] = {stretch_stiffness, bend_stiffness, bend_stiffness_2,
                                twist_stiffness};
  for (double s : stiffnesses) {
    if (!(s > 0.0) || !std::isfinite(s)) return fail("stiffnesses must be positive and finite");
  }
  if (!std::isfinite(natural_curvature) || !std::isfinite(natural_curvature_2))
    return fail("natural curvature must be finite");
  if (!(radius >= 0.0) || !std::isfinite(radius)) return fail("radius must be >= 0");
  if (!clamp_position.allFinite()) return fail("clamp position must be finite");
  for (const M3* r : {&clamp_rotation, &grasp_rotation}) {
    if (!r->allFinite() || ((*r).transpose() * (*r) - M3::Identity()).norm() > 1e-9 ||
        r->determinant() < 0.0) {
      return fail("clamp and grasp rotations must be proper rotation matrices");
    }
  }
  return true;
}

RodModel::RodModel(const RodParams& params) : p_(params) {
  std::string error;
  if (!p_.IsValid(&error)) throw std::invalid_argument(error);
  n_ = p_.n;
  nx_ = 4 * n_ - 11;
  nu_ = p_.free_start ? 12 : 6;
  rest_ = p_.length / n_;
  // Uniform rest edges: the Voronoi length ℓ̄ = ℓ at every interior vertex.
  stiffness_.c1 = p_.bend_stiffness / rest_;
  stiffness_.c2 = p_.bend_stiffness_2 / rest_;
  stiffness_.ct = p_.twist_stiffness / rest_;
  stiffness_.kappa1_bar = p_.natural_curvature * rest_;
  stiffness_.kappa2_bar = p_.natural_curvature_2 * rest_;
  assembly_ = internal::HessianAssembly(nx_, nu_);
  BuildTerms();
  ResetHistory();
}

void RodModel::ResetHistory() {
  // Reference frames of the rest rod: straight along the clamp, no turns at the grasp.
  sources_.assign(n_, FrameSource{p_.clamp_rotation.col(0), p_.clamp_rotation.col(1)});
  twist_near_.assign(n_, 0.0);
  grasp_theta_near_ = 0.0;
  start_theta_near_ = 0.0;
  const GraspMaps gm = Grasp(Vec::Zero(nu_), false);
  grasp_theta_near_ = gm.end.theta;
  if (p_.free_start) start_theta_near_ = gm.start.theta;
}

int RodModel::NodeIndex(int k) const {
  return (k >= 2 && k <= n_ - 2) ? 4 * k - 7 : -1;
}
int RodModel::ThetaIndex(int j) const {
  if (j < 1 || j > n_ - 2) return -1;
  return j == 1 ? 0 : 4 * j - 4;
}

void RodModel::BuildTerms() {
  const bool free = p_.free_start;
  auto node_code = [&](int k, int c) {
    if (k == 0) return free ? -12 - c : -1;
    if (k == 1) return free ? -9 - c : -1;
    if (k == n_ - 1) return -2 - c;
    if (k == n_) return -5 - c;
    return NodeIndex(k) + c;
  };
  auto theta_code = [&](int j) {
    if (j == 0) return free ? -15 : -1;
    if (j == n_ - 1) return -8;
    return ThetaIndex(j);
  };
  auto add = [&](Term term) {
    int vars[kMaxVars];
    int count = 0;
    for (int r = 0; r < term.nloc; ++r) {
      term.grasp = term.grasp || term.code[r] <= -2;
      term.at_start = term.at_start || term.code[r] <= -9;
    }
    if (!term.grasp) {
      for (int r = 0; r < term.nloc; ++r) vars[count++] = term.code[r];
    } else {
      for (int r = 0; r < term.nloc; ++r) {
        term.pos[r] = -1;
        if (term.code[r] >= 0) {
          term.pos[r] = count;
          vars[count++] = term.code[r];
        }
      }
      // Controls: u = (grasp of edge 0, grasp of edge n-1) without a clamp.
      const int offset = free && !term.at_start ? 6 : 0;
      for (int c = 0; c < 6; ++c) vars[count++] = nx_ + offset + c;
    }
    assembly_.AddTerm(vars, count);
    terms_.push_back(term);
  };
  // Stretching of the edges between the clamp and the grasp (edges 0 and n-1 keep ℓ).
  for (int j = 1; j <= n_ - 2; ++j) {
    Term term;
    term.index = j;
    term.nloc = 6;
    for (int c = 0; c < 3; ++c) {
      term.code[c] = node_code(j, c);
      term.code[3 + c] = node_code(j + 1, c);
    }
    add(term);
  }
  for (int i = 1; i <= n_ - 1; ++i) {
    Term term;
    term.vertex = true;
    term.index = i;
    term.nloc = 11;
    for (int a = 0; a < 3; ++a) {
      for (int c = 0; c < 3; ++c) term.code[3 * a + c] = node_code(i - 1 + a, c);
    }
    term.code[9] = theta_code(i - 1);
    term.code[10] = theta_code(i);
    add(term);
  }
  RegisterContact();
  assembly_.Finalize();
  for (int t = 0; t < static_cast<int>(terms_.size()); ++t) {
    if (assembly_.TouchesControls(t)) control_terms_.push_back(t);
  }
}

RodModel::GraspMaps RodModel::Grasp(const Vec& u, bool derivatives, bool world_rotation) const {
  GraspMaps gm;
  gm.end = OneGrasp(u, false, derivatives, world_rotation);
  if (p_.free_start) gm.start = OneGrasp(u, true, derivatives, world_rotation);
  return gm;
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
  if (!derivatives) {
    // Values only (Energy, line searches): the rotation and one angle.
    const M3 r = rod::ExpMap(phi) * r_start;
    const V3 t = r.col(0);
    gm.xn = pos;
    gm.xn1 = pos + side * t;
    V3 a, b;
    rod::ReferenceFrame(src, t, &a, &b);
    gm.theta = rod::AngleAbout(t, a, r.col(1), near);
    return gm;
  }
  // Derivatives in φ, or in a world rotation δ of the current orientation
  // (exp([δ]×) R(u), δ = 0) for the torque.
  const M3 rot = world_rotation ? M3(rod::ExpMap(phi) * r_start) : r_start;
  const V3 at = world_rotation ? V3::Zero() : phi;
  const JetVec t = rod::RotateJet(at, rot.col(0));
  const JetVec m1 = rod::RotateJet(at, rot.col(1));
  gm.xn = pos;
  gm.xn1 = pos + side * t.Value();
  // θ_{n-1}: the angle of m1 about t from the time-parallel reference director
  // a = P_{t_s}^{t} a_s = a_s - (a_s·t)/(1 + t_s·t) (t_s + t) (a_s ⊥ t_s).
  const FrameSource& s = src;
  const Jet k = Dot(s.a, t) * rod::Inverse(Jet::Constant(1.0) + Dot(s.t, t));
  const JetVec a = JetVec::Constant(s.a) - k * (JetVec::Constant(s.t) + t);
  const JetVec b = rod::CrossJ(t, a);
  const Jet theta = rod::Atan2(Dot(b, m1), Dot(a, m1));
  gm.theta = near + std::remainder(theta.v - near, 2.0 * std::numbers::pi);
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

V3 RodModel::Node(int k, const Vec& x, const GraspMaps& gm) const {
  if (k == 0) return p_.free_start ? gm.start.xn : p_.clamp_position;
  if (k == 1) return p_.free_start ? gm.start.xn1 : V3(p_.clamp_position + rest_ * p_.clamp_rotation.col(0));
  if (k == n_ - 1) return gm.end.xn1;
  if (k == n_) return gm.end.xn;
  return x.segment<3>(NodeIndex(k));
}

double RodModel::Theta(int j, const Vec& x, const GraspMaps& gm) const {
  if (j == 0) return p_.free_start ? gm.start.theta : 0.0;
  if (j == n_ - 1) return gm.end.theta;
  return x[ThetaIndex(j)];
}

template <class F>
void RodModel::Local(int t, const Vec& x, const GraspMaps& gms, bool want_h, F&& f) const {
  const Term& term = terms_[t];
  const GraspMap& gm = term.at_start ? gms.start : gms.end;
  Eigen::Matrix<double, kMaxLocal, 1> gy;
  Eigen::Matrix<double, kMaxLocal, kMaxLocal> hy;
  const int i = term.index;
  if (term.grasp) {
    // The chain rule below multiplies full fixed-size blocks (no dynamic temporaries).
    gy.setZero();
    hy.setZero();
  }
  if (!term.vertex) {
    Eigen::Matrix<double, 6, 1> g6;
    Eigen::Matrix<double, 6, 6> h6;
    // ½ EA (|e|/ℓ - 1)² ℓ = (EA / 2ℓ) (|e| - ℓ)²  [DER (2) with the stretching of DVT §4]
    internal::StretchTerm<3>(Node(i, x, gms), Node(i + 1, x, gms),
                             0.5 * p_.stretch_stiffness / rest_, rest_, &g6,
                             want_h ? &h6 : nullptr);
    gy.head<6>() = g6;
    if (want_h) hy.topLeftCorner<6, 6>() = h6;
  } else {
    const V3 xa = Node(i - 1, x, gms), xb = Node(i, x, gms), xc = Node(i + 1, x, gms);
    rod::Vec8 g8;
    rod::Mat8 h8;
    rod::VertexEnergy(xb - xa, xc - xb, Theta(i - 1, x, gms), Theta(i, x, gms), sources_[i - 1],
                      sources_[i], twist_near_[i], stiffness_, &g8, want_h ? &h8 : nullptr);
    // (e0, e1) = (x_i - x_{i-1}, x_{i+1} - x_i).
    gy.segment<3>(0) = -g8.segment<3>(0);
    gy.segment<3>(3) = g8.segment<3>(0) - g8.segment<3>(3);
    gy.segment<3>(6) = g8.segment<3>(3);
    gy.segment<2>(9) = g8.tail<2>();
    if (want_h) {
      // Hy = Lᵀ H8 L with node a's edge coefficients D(a, ·) = (-1, 0), (1, -1), (0, 1),
      // block by block (the dense product would cost several times more).
      static constexpr double kD[3][2] = {{-1.0, 0.0}, {1.0, -1.0}, {0.0, 1.0}};
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) {
          M3 blk = M3::Zero();
          for (int e = 0; e < 2; ++e) {
            if (kD[a][e] == 0.0) continue;
            for (int f = 0; f < 2; ++f) {
              if (kD[b][f] != 0.0) blk += (kD[a][e] * kD[b][f]) * h8.block<3, 3>(3 * e, 3 * f);
            }
          }
          hy.block<3, 3>(3 * a, 3 * b) = blk;
        }
        Eigen::Matrix<double, 3, 2> side = Eigen::Matrix<double, 3, 2>::Zero();
        for (int e = 0; e < 2; ++e) {
          if (kD[a][e] != 0.0) side += kD[a][e] * h8.block<3, 2>(3 * e, 6);
        }
        hy.block<3, 2>(3 * a, 9) = side;
        hy.block<2, 3>(9, 3 * a) = side.transpose();
      }
      hy.block<2, 2>(9, 9) = h8.block<2, 2>(6, 6);
    }
  }
  const int nloc = term.nloc;
  if (!term.grasp) {
    f(gy.data(), hy.data(), kMaxLocal);
    return;
  }
  // Chain rule through the grasp map: y = C z (+ curvature of the grasp coordinates).
  const int k = assembly_.TermSize(t);
  Eigen::Matrix<double, kMaxLocal, kMaxVars> c = Eigen::Matrix<double, kMaxLocal, kMaxVars>::Zero();
  for (int r = 0; r < nloc; ++r) {
    if (term.code[r] >= 0) {
      c(r, term.pos[r]) = 1.0;
    } else if (term.code[r] <= -2) {
      c.block<1, 6>(r, k - 6) = gm.jac.row(GraspCoordinate(term.code[r]));
    }
  }
  Eigen::Matrix<double, kMaxVars, 1> ga;
  Eigen::Matrix<double, kMaxVars, kMaxVars> ha;
  ga.noalias() = c.transpose() * gy;
  if (want_h) {
    const Eigen::Matrix<double, kMaxLocal, kMaxVars> hc = hy * c;
    ha.noalias() = c.transpose() * hc;
    for (int r = 0; r < nloc; ++r) {
      if (term.code[r] <= -2) ha.block<3, 3>(k - 3, k - 3) += gy[r] * gm.hess_phi[GraspCoordinate(term.code[r])];
    }
  }
  f(ga.data(), ha.data(), kMaxVars);
}

double RodModel::Energy(const Vec& x, const Vec& u) const {
  const GraspMaps gm = Grasp(u, false);
  double e = 0.0;
  for (const Term& term : terms_) {
    const int i = term.index;
    if (!term.vertex) {
      e += internal::StretchTerm<3>(Node(i, x, gm), Node(i + 1, x, gm),
                                    0.5 * p_.stretch_stiffness / rest_, rest_, nullptr, nullptr);
    } else {
      const V3 xa = Node(i - 1, x, gm), xb = Node(i, x, gm), xc = Node(i + 1, x, gm);
      e += rod::VertexEnergy(xb - xa, xc - xb, Theta(i - 1, x, gm), Theta(i, x, gm),
                             sources_[i - 1], sources_[i], twist_near_[i], stiffness_, nullptr,
                             nullptr);
    }
  }
  if (contact_.enabled()) e += contact_.Energy(ContactNodes(x, gm));
  return e;
}

void RodModel::Gradient(const Vec& x, const Vec& u, Vec* g) const {
  if (g->size() != nx_) g->resize(nx_);
  g->setZero();
  const GraspMaps gm = Grasp(u, true);
  for (int t = 0; t < static_cast<int>(terms_.size()); ++t) {
    Local(t, x, gm, false,
          [&](const double* lg, const double*, int) { assembly_.AddGradient(t, lg, g->data()); });
  }
  if (contact_.enabled()) contact_.AddGradient(ContactNodes(x, gm), g->data());
}

void RodModel::Hessian(const Vec& x, const Vec& u, SparseMatrix* h) const {
  // StoreHessian: every elastic slot is reached by an elastic term first, so no clearing
  // pass; slots only a contact pair reaches are cleared when contact is on.
  double* values = assembly_.Values(h, contact_.enabled());
  const GraspMaps gm = Grasp(u, true);
  for (int t = 0; t < static_cast<int>(terms_.size()); ++t) {
    Local(t, x, gm, true, [&](const double*, const double* lh, int ld) {
      assembly_.StoreHessian(t, lh, ld, values);
    });
  }
  if (contact_.enabled()) contact_.AddHessian(ContactNodes(x, gm), values);
}

void RodModel::GradientAndHessian(const Vec& x, const Vec& u, Vec* g, SparseMatrix* h) const {
  if (g->size() != nx_) g->resize(nx_);
  g->setZero();
  double* values = assembly_.Values(h, contact_.enabled());
  const GraspMaps gm = Grasp(u, true);
  for (int t = 0; t < static_cast<int>(terms_.size()); ++t) {
    Local(t, x, gm, true, [&](const double* lg, const double* lh, int ld) {
      assembly_.AddGradient(t, lg, g->data());
      assembly_.StoreHessian(t, lh, ld, values);
    });
  }
  if (contact_.enabled()) {
    contact_.AddGradient(ContactNodes(x, gm), g->data());
    contact_.AddHessian(ContactNodes(x, gm), values);
  }
}

void RodModel::ControlGradient(const Vec& x, const Vec& u, Vec* eu) const {
  if (eu->size() != nu_) eu->resize(nu_);
  eu->setZero();
  const GraspMaps gm = Grasp(u, true);
  for (int t : control_terms_) {
    Local(t, x, gm, false, [&](const double* lg, const double*, int) {
      assembly_.AddControlGradient(t, lg, eu->data());
    });
  }
  if (contact_.enabled()) contact_.AddControlGradient(ContactNodes(x, gm), ContactControls(gm), eu->data());
}

bool RodModel::GraspTorque(const Vec& x, const Vec& u, Eigen::Vector3d* torque) const {
  // The E_u of a grasp map differentiated in a world rotation δ instead of φ: the
  // rotation-vector gradient E_φ = J_l(φ)ᵀ E_δ loses the torque where J_l is singular
  // (|φ| = 2π, 4π: two turns of a roll).
  const GraspMaps gm = Grasp(u, true, true);
  Eigen::Matrix<double, 12, 1> e = Eigen::Matrix<double, 12, 1>::Zero();
  for (int t : control_terms_) {
    Local(t, x, gm, false, [&](const double* lg, const double*, int) {
      assembly_.AddControlGradient(t, lg, e.data());
    });
  }
  if (contact_.enabled()) contact_.AddControlGradient(ContactNodes(x, gm), ContactControls(gm), e.data());
  *torque = -e.segment<3>(3);  // the first grasp's (edge 0's without a clamp)
  return true;
}

void RodModel::MixedHessian(const Vec& x, const Vec& u, Mat* exu) const {
  if (exu->rows() != nx_ || exu->cols() != nu_) exu->resize(nx_, nu_);
  exu->setZero();
  const GraspMaps gm = Grasp(u, true);
  for (int t : control_terms_) {
    Local(t, x, gm, true, [&](const double*, const double* lh, int ld) {
      assembly_.AddMixedHessian(t, lh, ld, exu);
    });
  }
  if (contact_.enabled()) contact_.AddMixedHessian(ContactNodes(x, gm), ContactControls(gm), exu);
}

void RodModel::ControlHessian(const Vec& x, const Vec& u, Mat* euu) const {
  if (euu->rows() != nu_ || euu->cols() != nu_) euu->resize(nu_, nu_);
  euu->setZero();
  const GraspMaps gm = Grasp(u, true);
  for (int t : control_terms_) {
    Local(t, x, gm, true, [&](const double*, const double* lh, int ld) {
      assembly_.AddControlHessian(t, lh, ld, euu);
    });
  }
  if (contact_.enabled()) contact_.AddControlHessian(ContactNodes(x, gm), ContactControls(gm), euu);
}

Vec RodModel::InitialState(const Vec& u) const {
  const GraspMaps gm = Grasp(u, false);
  Vec x = Vec::Zero(nx_);
  const V3 x1 = Node(1, x, gm);
  // A slack rod starts bowed out towards the clamp's m1 (a compressed straight rod is a
  // saddle whose bending modes the start solve cannot pick between): the free span
  // x_1 .. x_{n-1} of chord D and rest length L' follows y = A/2 (1 - cos 2πs) with
  // A = (2/π) sqrt(D (L' - D)), the arc of length ≈ L'.
  const V3 chord = gm.end.xn1 - x1;
  const double d = chord.norm(), free = (n_ - 2) * rest_;
  V3 side = V3::Zero();
  if (d > 0.0 && free - d > 1e-9 * p_.length) {
    const V3 t = chord / d;
    for (int c = 1; c <= 2 && side.norm() < 0.5; ++c) {
      side = p_.clamp_rotation.col(c) - p_.clamp_rotation.col(c).dot(t) * t;
    }
    side *= (2.0 / std::numbers::pi) * std::sqrt(d * (free - d)) / side.norm();
  }
  for (int k = 2; k <= n_ - 2; ++k) {
    const double s = static_cast<double>(k - 1) / (n_ - 2);
    x.segment<3>(NodeIndex(k)) = x1 + s * chord + 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * s)) * side;
  }
  const double theta0 = Theta(0, x, gm);
  for (int j = 1; j <= n_ - 2; ++j) x[ThetaIndex(j)] = theta0 + (gm.end.theta - theta0) * j / (n_ - 1);
  return x;
}

void RodModel::NodePositions(const Vec& x, const Vec& u, Eigen::Matrix3Xd* nodes) const {
  if (nodes->cols() != n_ + 1) nodes->resize(3, n_ + 1);
  const GraspMaps gm = Grasp(u, false);
  for (int k = 0; k <= n_; ++k) nodes->col(k) = Node(k, x, gm);
}

double RodModel::Probe(const Vec& x, const Vec& u) const {
  const GraspMaps gm = Grasp(u, false);
  const V3 c = Node(0, Vec(), gm);
  V3 d = gm.end.xn - c;
  const double len = d.norm();
  d = len > 1e-12 * p_.length ? V3(d / len) : V3::Zero();
  double probe = 0.0;
  for (int k = 0; k <= n_; ++k) {
    const V3 r = Node(k, x, gm) - c;
    probe = std::max(probe, (r - r.dot(d) * d).norm());
  }
  return probe;
}

double RodModel::ForceScale() const {
  return p_.bend_stiffness / (p_.length * p_.length);
}

Vec RodModel::MaterialAngles(const Vec& x, const Vec& u) const {
  const GraspMaps gm = Grasp(u, false);
  Vec theta(n_);
  for (int j = 0; j < n_; ++j) theta[j] = Theta(j, x, gm);
  return theta;
}

V3 RodModel::MaterialDirector(const Vec& x, const Vec& u, int j) const {
  const GraspMaps gm = Grasp(u, false);
  const V3 t = (Node(j + 1, x, gm) - Node(j, x, gm)).normalized();
  V3 a, b;
  rod::ReferenceFrame(sources_[j], t, &a, &b);
  const double th = Theta(j, x, gm);
  return std::cos(th) * a + std::sin(th) * b;
}

void RodModel::AcceptState(const Vec& x, const Vec& u) {
  const GraspMaps gm = Grasp(u, false);
  // Continued values first, against the old sources (at the accepted state the new
  // frames equal the old ones carried there, so E(x, u) does not change).
  for (int i = 1; i <= n_ - 1; ++i) {
    twist_near_[i] = rod::ReferenceTwist(Node(i, x, gm) - Node(i - 1, x, gm),
                                         Node(i + 1, x, gm) - Node(i, x, gm), sources_[i - 1],
                                         sources_[i], twist_near_[i]);
  }
  grasp_theta_near_ = gm.end.theta;
  if (p_.free_start) start_theta_near_ = gm.start.theta;
  for (int j = 0; j < n_; ++j) {
    const V3 t = (Node(j + 1, x, gm) - Node(j, x, gm)).normalized();
    V3 a, b;
    rod::ReferenceFrame(sources_[j], t, &a, &b);
    // Re-orthonormalise so rounding does not accumulate over many updates.
    sources_[j].t = t;
    sources_[j].a = (a - a.dot(t) * t).normalized();
  }
}

// ---------------------------------------------------------------------------------
// Registration: the scene's `model: rod`. The clamp sits at the origin with its body
// axes along the world's (the rod leaves along +x); the grasp starts with the same
// orientation, so u = (X, Y, Z, φ) with φ = 0 holds the last edge along +x and a roll
// about the tangent is φ = (roll, 0, 0).
ModelRegistration RodRegistration() {
  ModelRegistration r;
  r.name = "rod";
  r.doc = "discrete elastic rod that twists (Bergou et al. 2008/2010): full-pose clamp at the origin "
          "along +x and grasp u = (X, Y, Z, rotation vector)";
  constexpr double kInf = std::numeric_limits<double>::infinity();
  auto positive = [&](const char* name, double def, const char* units, const char* doc) {
    return ParamSpec{.name = name, .default_value = def, .min = 0.0, .min_inclusive = false,
                     .max = kInf, .units = units, .doc = doc};
  };
  r.params = {
      {.name = "n", .kind = ParamKind::kInteger, .default_value = 20, .min = 3,
       .doc = "number of edges (the clamp and the grasp hold one each)"},
      positive("length", 1.0, "m", "rest length L (every edge L / n)"),
      positive("stretch_stiffness", 1000.0, "N", "EA in 1/2 EA (|e|/l - 1)^2 l per edge"),
      positive("bend_stiffness", 1.0, "N m^2", "B1 = EI for bending towards m1 (kappa1) [DER (4)]"),
      {.name = "bend_stiffness_2", .default_value = 0.0, .min = 0.0, .units = "N m^2",
       .doc = "B2 for bending towards m2 (kappa2); 0 = bend_stiffness (a round rod), >> B1 a ribbon"},
      positive("twist_stiffness", 1.0, "N m^2", "GJ in 1/2 GJ (twist)^2 / l [DVT (4)]"),
      {.name = "natural_curvature", .default_value = 0.0, .units = "1/m",
       .doc = "natural material curvature kappa1-bar (bending towards m1)"},
      {.name = "natural_curvature_2", .default_value = 0.0, .units = "1/m",
       .doc = "natural material curvature kappa2-bar (bending towards m2)"},
      {.name = "clamp", .kind = ParamKind::kBool, .default_value = 1.0,
       .doc = "false: no clamp, a first grasp holds edge 0 (u = (its pose, the last edge's pose))"},
      {.name = "radius", .default_value = 0.01, .min = 0.0, .units = "m",
       .doc = "tube radius (drawing; the capsule radius of self-contact)"},
  };
  for (ParamSpec& spec : internal::ContactParamSpecs()) r.params.push_back(std::move(spec));
  r.factory = [](const ModelParams& mp) -> std::unique_ptr<Model> {
    RodParams p;
    p.n = mp.Integer("n");
    p.length = mp.Number("length");
    p.stretch_stiffness = mp.Number("stretch_stiffness");
    p.bend_stiffness = mp.Number("bend_stiffness");
    const double b2 = mp.Number("bend_stiffness_2");
    p.bend_stiffness_2 = b2 > 0.0 ? b2 : p.bend_stiffness;
    p.twist_stiffness = mp.Number("twist_stiffness");
    p.natural_curvature = mp.Number("natural_curvature");
    p.natural_curvature_2 = mp.Number("natural_curvature_2");
    p.radius = mp.Number("radius");
    p.free_start = !mp.Bool("clamp");
    p.contact = internal::ReadContactParams(mp);
    return std::make_unique<RodModel>(p);
  };
  r.check = [](const ModelParams& mp, std::string* error) {
    if (mp.Bool("clamp") || mp.Integer("n") >= 5) return true;
    if (error != nullptr) *error = "params.n: expected an integer >= 5 with clamp: false (two grasps)";
    return false;
  };
  r.capabilities.grasp_sites = [](const ModelParams& mp) {
    const std::string last = "edge " + std::to_string(mp.Integer("n") - 1);
    return mp.Bool("clamp") ? std::vector<std::string>{last} : std::vector<std::string>{"edge 0", last};
  };
  r.capabilities.grasp_layout = [](const ModelParams&) {
    return GraspLayout{.spatial_dimension = 3, .grip_rotation = true};
  };
  return r;
}

}  // namespace snapthread
