#include "models/rod_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace snapthread {

using rod::FrameSource;
using V3 = Eigen::Vector3d;
constexpr int kMaxVars = internal::HessianAssembly::kMaxTermVars;

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
  edges_.resize(n_);
  grasp_cache_u_ = Vec::Zero(nu_);
  twist_cache_.assign(n_, 0.0);
  for (StateKey* key : {&energy_key_, &band_key_, &frames_key_}) {
    key->x = Vec::Zero(nx_);
    key->u = Vec::Zero(nu_);
  }
  BuildTerms();
  band_cache_.assign(static_cast<size_t>(nx_) * (assembly_.Bandwidth() + 1), 0.0);
  ResetHistory();
}

void RodModel::ResetHistory() {
  // Reference frames of the rest rod: straight along the clamp, no turns at the grasp.
  sources_.assign(n_, FrameSource{p_.clamp_rotation.col(0), p_.clamp_rotation.col(1)});
  twist_near_.assign(n_, 0.0);
  InvalidateCaches();
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
    // One block of the state (AddInteriorTerm): a vertex's coordinates in its local
    // order sit at these offsets from x_{i-1}'s; an edge's x_{j+1} four after x_j.
    static constexpr int kVertexOffset[11] = {0, 1, 2, 4, 5, 6, 8, 9, 10, 3, 7};
    static constexpr int kEdgeOffset[6] = {0, 1, 2, 4, 5, 6};
    if (!term.grasp && term.code[0] >= 0) {
      bool block = true;
      for (int r = 0; r < term.nloc; ++r) {
        const int offset = term.vertex ? kVertexOffset[r] : kEdgeOffset[r];
        block = block && term.code[r] == term.code[0] + offset;
      }
      if (block) term.first = term.code[0];
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
  if (frames_key_.Matches(x, u)) {
    // The last pass over every term was at x: its frames and reference twists are the
    // values computed below (the same operations, the same bits).
    for (int i = 1; i <= n_ - 1; ++i) twist_near_[i] = twist_cache_[i];
    grasp_theta_near_ = gm.end.theta;
    if (p_.free_start) start_theta_near_ = gm.start.theta;
    for (int j = 0; j < n_; ++j) {
      const V3& t = edges_[j].t;
      sources_[j].t = t;
      sources_[j].a = (edges_[j].a - edges_[j].a.dot(t) * t).normalized();
    }
    InvalidateCaches();
    return;
  }
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
  InvalidateCaches();  // the grasp maps and energies depend on the frames and angles moved here
}

}  // namespace snapthread
