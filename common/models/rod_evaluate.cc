// The rod's energy and its derivatives, term by term (rod_model.h): the stretching of the
// free edges and the bending and twist of every interior vertex (rod_energy.h), each edge's
// frame computed once per evaluation (PrepareEdges), then the chain rule through the grasp
// map for the terms that touch a grasp, then the assembly (hessian_assembly.h).
#include <algorithm>
#include <cstring>

#include "models/chain_terms.h"
#include "models/rod_model.h"

namespace snapthread {
namespace {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;
constexpr int kMaxVars = internal::HessianAssembly::kMaxTermVars;

// The grasp coordinate g of a local code (RodModel::Term): -2 - g, or -9 - g for the grasp
// of edge 0.
int GraspCoordinate(int code) { return code <= -9 ? -9 - code : -2 - code; }

}  // namespace

bool RodModel::StateKey::Matches(const Vec& x1, const Vec& u1) const {
  return valid && x1.size() == x.size() && u1.size() == u.size() &&
         std::memcmp(x1.data(), x.data(), sizeof(double) * x.size()) == 0 &&
         std::memcmp(u1.data(), u.data(), sizeof(double) * u.size()) == 0;
}

void RodModel::StateKey::Set(const Vec& x1, const Vec& u1) {
  valid = x1.size() == x.size() && u1.size() == u.size();  // sized at construction
  if (valid) {
    x = x1;
    u = u1;
  }
}

void RodModel::InvalidateCaches() {
  grasp_cache_valid_ = false;
  energy_key_.valid = false;
  band_key_.valid = false;
  frames_key_.valid = false;
}

void RodModel::PrepareEdges(const Vec& x, const Vec& u, const GraspMaps& gm, bool want_h,
                            bool control_terms_only) const {
  if (frames_key_.valid && !frames_key_.Matches(x, u)) frames_key_.valid = false;
  auto edge = [&](int j) {
    rod::ComputeEdgeFrame(Node(j + 1, x, gm) - Node(j, x, gm), Theta(j, x, gm), sources_[j], want_h, &edges_[j]);
  };
  if (!control_terms_only) {
    for (int j = 0; j < n_; ++j) edge(j);
    return;
  }
  for (int t : control_terms_) {
    const Term& term = terms_[t];
    if (term.vertex) edge(term.index - 1);
    edge(term.index);
  }
}

double RodModel::StretchEnergy(int j, Eigen::Matrix<double, 6, 1>* g, Eigen::Matrix<double, 6, 6>* h) const {
  // ½ EA (|e|/ℓ - 1)² ℓ = (EA / 2ℓ) (|e| - ℓ)²  [DER (2) with the stretching of DVT §4]
  // (the segment from 0 to e: e - 0 is e exactly).
  const double e = internal::StretchTerm<3>(V3::Zero(), edges_[j].e, 0.5 * p_.stretch_stiffness / rest_, rest_, g, h);
  if (h != nullptr) {
    // Its lower triangle mirrored: symmetric to the bit (the outer product w wᵀ scaled is
    // not always), so E_xx is, and its lower band gives back the whole matrix.
    for (int c = 0; c < 6; ++c) {
      for (int r = c + 1; r < 6; ++r) (*h)(c, r) = (*h)(r, c);
    }
  }
  return e;
}

double RodModel::TermDerivatives(const Term& term, bool want_h, LocalGradient* gy, LocalHessian* hy) const {
  const int i = term.index;
  double energy = 0.0;
  if (!term.vertex) {
    Eigen::Matrix<double, 6, 1> g6;
    Eigen::Matrix<double, 6, 6> h6;
    energy = StretchEnergy(i, &g6, want_h ? &h6 : nullptr);
    gy->head<6>() = g6;
    if (want_h) hy->topLeftCorner<6, 6>() = h6;
  } else {
    rod::Vec8 g8;
    rod::Mat8 h8;
    energy = rod::VertexEnergy(edges_[i - 1], edges_[i], twist_near_[i], stiffness_, &g8, want_h ? &h8 : nullptr,
                               &twist_cache_[i]);
    // (e0, e1) = (x_i - x_{i-1}, x_{i+1} - x_i).
    gy->segment<3>(0) = -g8.segment<3>(0);
    gy->segment<3>(3) = g8.segment<3>(0) - g8.segment<3>(3);
    gy->segment<3>(6) = g8.segment<3>(3);
    gy->segment<2>(9) = g8.tail<2>();
    if (want_h) {
      // Hy = Lᵀ H8 L with node a's edge coefficients (-1, 0), (1, -1), (0, 1): the lower
      // node blocks from the edge blocks H_ef (H8 is symmetric to the bit), then their mirror.
      const M3 h00 = h8.block<3, 3>(0, 0), h10 = h8.block<3, 3>(3, 0), h11 = h8.block<3, 3>(3, 3);
      hy->block<3, 3>(0, 0) = h00;
      hy->block<3, 3>(3, 0) = h10 - h00;
      hy->block<3, 3>(6, 0) = -h10;
      hy->block<3, 3>(3, 3) = (h00 + h11) - (h10 + h10.transpose());  // symmetric to the bit
      hy->block<3, 3>(6, 3) = h10 - h11;
      hy->block<3, 3>(6, 6) = h11;
      hy->block<3, 3>(0, 3) = hy->block<3, 3>(3, 0).transpose();
      hy->block<3, 3>(0, 6) = hy->block<3, 3>(6, 0).transpose();
      hy->block<3, 3>(3, 6) = hy->block<3, 3>(6, 3).transpose();
      const Eigen::Matrix<double, 3, 2> s0 = h8.block<3, 2>(0, 6), s1 = h8.block<3, 2>(3, 6);
      hy->block<3, 2>(0, 9) = -s0;
      hy->block<3, 2>(3, 9) = s0 - s1;
      hy->block<3, 2>(6, 9) = s1;
      hy->block<2, 9>(9, 0) = hy->block<9, 2>(0, 9).transpose();
      hy->block<2, 2>(9, 9) = h8.block<2, 2>(6, 6);
    }
  }
  return energy;
}

void RodModel::GraspChainRule(int t, const GraspMaps& gms, bool want_h, const LocalGradient& gy, const LocalHessian& hy,
                              TermGradient* ga, TermHessian* ha) const {
  // Chain rule through the grasp map y = y(z): state coordinates map one to one, the
  // grasp coordinates G through rows J_G of the map's Jacobian (over the 6 controls at
  // local columns s0..s0+5), plus the map's curvature in φ weighted by E_y:
  //   E_z = (E_y(states), J_Gᵀ E_y(G)),
  //   E_zz = [[H_SS, H_SG J_G], [J_Gᵀ H_GS, J_Gᵀ H_GG J_G + Σ_G E_y ∂²y/∂φ²]].
  const Term& term = terms_[t];
  const GraspMap& gm = term.at_start ? gms.start : gms.end;
  const int nloc = term.nloc;
  const int s0 = assembly_.TermSize(t) - 6;
  int rows[kMaxLocal], coord[kMaxLocal];
  int ng = 0;
  for (int r = 0; r < nloc; ++r) {
    if (term.code[r] >= 0) {
      (*ga)[term.pos[r]] = gy[r];
    } else if (term.code[r] <= -2) {
      rows[ng] = r;
      coord[ng++] = GraspCoordinate(term.code[r]);
    }
  }
  for (int c = 0; c < 6; ++c) {
    double sum = 0.0;
    for (int q = 0; q < ng; ++q) sum += gy[rows[q]] * gm.jac(coord[q], c);
    (*ga)[s0 + c] = sum;
  }
  if (want_h) {
    Eigen::Matrix<double, kMaxLocal, 6> m;  // H_yG J_G, rows 0..nloc-1
    for (int c = 0; c < 6; ++c) {
      for (int r = 0; r < nloc; ++r) {
        double sum = 0.0;
        for (int q = 0; q < ng; ++q) sum += hy(r, rows[q]) * gm.jac(coord[q], c);
        m(r, c) = sum;
      }
    }
    for (int b = 0; b < nloc; ++b) {
      if (term.code[b] < 0) continue;
      const int pb = term.pos[b];
      for (int a = 0; a < nloc; ++a) {
        if (term.code[a] >= 0) (*ha)(term.pos[a], pb) = hy(a, b);
      }
      for (int c = 0; c < 6; ++c) {
        (*ha)(pb, s0 + c) = m(b, c);
        (*ha)(s0 + c, pb) = m(b, c);
      }
    }
    // The control block: its lower triangle, then the mirror (symmetric to the bit).
    for (int c = 0; c < 6; ++c) {
      for (int r = c; r < 6; ++r) {
        double sum = 0.0;
        for (int q = 0; q < ng; ++q) sum += gm.jac(coord[q], r) * m(rows[q], c);
        if (c >= 3) {
          for (int q = 0; q < ng; ++q) sum += gy[rows[q]] * gm.hess_phi[coord[q]](r - 3, c - 3);
        }
        (*ha)(s0 + r, s0 + c) = sum;
        (*ha)(s0 + c, s0 + r) = sum;
      }
    }
  }
}

template <class F>
double RodModel::Local(int t, const GraspMaps& gms, bool want_h, F&& f) const {
  const Term& term = terms_[t];
  LocalGradient gy;
  LocalHessian hy;
  const double energy = TermDerivatives(term, want_h, &gy, &hy);
  if (!term.grasp) {
    f(gy.data(), hy.data(), kMaxLocal);
    return energy;
  }
  TermGradient ga;
  TermHessian ha;
  GraspChainRule(t, gms, want_h, gy, hy, &ga, &ha);
  f(ga.data(), ha.data(), kMaxVars);
  return energy;
}

double RodModel::AddInteriorTerm(const Term& term, double* g, double* band, int b) const {
  return term.vertex ? AddInteriorVertex(term, g, band, b) : AddInteriorEdge(term, g, band, b);
}

double RodModel::AddInteriorEdge(const Term& term, double* g, double* band, int b) const {
  // The term's state block starts at v = term.first; A(v + r, v + c), r >= c, is at
  // row[c] with row = band + (v + r)(b + 1) + b - r (linalg/banded_ldlt.h's layout). The
  // values are Local()'s (Lᵀ H L for a vertex, by the same operations), each added once
  // to its slot as the assembly adds them: the same bits.
  const int v = term.first;
  const int ld = b + 1;
  auto row = [&](int r) { return band + static_cast<std::ptrdiff_t>(v + r) * ld + b - r; };
  const int i = term.index;
  // Edge i: x_i at v, x_{i+1} at v + 4 (θ_i, at v + 3, is not touched).
  Eigen::Matrix<double, 6, 1> g6;
  Eigen::Matrix<double, 6, 6> h6;
  const double e = StretchEnergy(i, &g6, band != nullptr ? &h6 : nullptr);
  for (int k = 0; k < 3; ++k) {
    g[v + k] += g6[k];
    g[v + 4 + k] += g6[3 + k];
  }
  if (band == nullptr) return e;
  for (int r = 0; r < 3; ++r) {
    double* d0 = row(r);
    for (int c = 0; c <= r; ++c) d0[c] += h6(r, c);
    double* d1 = row(4 + r);
    for (int c = 0; c < 3; ++c) d1[c] += h6(3 + r, c);
    for (int c = 0; c <= r; ++c) d1[4 + c] += h6(3 + r, 3 + c);
  }
  return e;
}

double RodModel::AddInteriorVertex(const Term& term, double* g, double* band, int b) const {
  // The band layout as in AddInteriorEdge.
  const int v = term.first;
  const int ld = b + 1;
  auto row = [&](int r) { return band + static_cast<std::ptrdiff_t>(v + r) * ld + b - r; };
  const int i = term.index;
  // Vertex i: x_{i-1}, θ_{i-1}, x_i, θ_i, x_{i+1} at v, v + 3, v + 4, v + 7, v + 8; the
  // edges (e0, e1) = (x_i - x_{i-1}, x_{i+1} - x_i) (Local()'s chain rule).
  rod::Vec8 g8;
  rod::Mat8 h8;
  const double e = rod::VertexEnergy(edges_[i - 1], edges_[i], twist_near_[i], stiffness_, &g8,
                                     band != nullptr ? &h8 : nullptr, &twist_cache_[i]);
  for (int k = 0; k < 3; ++k) {
    g[v + k] += -g8[k];
    g[v + 4 + k] += g8[k] - g8[3 + k];
    g[v + 8 + k] += g8[3 + k];
  }
  g[v + 3] += g8[6];
  g[v + 7] += g8[7];
  if (band == nullptr) return e;
  const M3 h00 = h8.block<3, 3>(0, 0), h10 = h8.block<3, 3>(3, 0), h11 = h8.block<3, 3>(3, 3);
  // The node blocks below the diagonal and on it (Local()'s expressions).
  const M3 n10 = h10 - h00, n20 = -h10, n21 = h10 - h11;
  const M3 n11 = (h00 + h11) - (h10 + h10.transpose());
  // Node a against θ_{i-1} (k = 0) and θ_i (k = 1): -s0, s0 - s1, s1 (s_e = H8 rows of e, angle columns).
  const Eigen::Matrix<double, 3, 2> s0 = h8.block<3, 2>(0, 6), s1 = h8.block<3, 2>(3, 6);
  const Eigen::Matrix<double, 3, 2> a0 = -s0, a1 = s0 - s1;
  for (int r = 0; r < 3; ++r) {
    double* d = row(r);  // x_{i-1}
    for (int c = 0; c <= r; ++c) d[c] += h00(r, c);
  }
  {
    double* d = row(3);  // θ_{i-1}
    for (int c = 0; c < 3; ++c) d[c] += a0(c, 0);
    d[3] += h8(6, 6);
  }
  for (int r = 0; r < 3; ++r) {
    double* d = row(4 + r);  // x_i
    for (int c = 0; c < 3; ++c) d[c] += n10(r, c);
    d[3] += a1(r, 0);
    for (int c = 0; c <= r; ++c) d[4 + c] += n11(r, c);
  }
  {
    double* d = row(7);  // θ_i
    for (int c = 0; c < 3; ++c) d[c] += a0(c, 1);
    d[3] += h8(7, 6);
    for (int c = 0; c < 3; ++c) d[4 + c] += a1(c, 1);
    d[7] += h8(7, 7);
  }
  for (int r = 0; r < 3; ++r) {
    double* d = row(8 + r);  // x_{i+1}
    for (int c = 0; c < 3; ++c) d[c] += n20(r, c);
    d[3] += s1(r, 0);
    for (int c = 0; c < 3; ++c) d[4 + c] += n21(r, c);
    d[7] += s1(r, 1);
    for (int c = 0; c <= r; ++c) d[8 + c] += h11(r, c);
  }
  return e;
}

double RodModel::Energy(const Vec& x, const Vec& u) const {
  // The energy of the last state evaluated (the same operations gave it: the same bits).
  if (energy_key_.Matches(x, u)) return energy_cache_;
  const GraspMaps gm = Grasp(u, false);
  PrepareEdges(x, u, gm, false, false);
  double e = 0.0;
  for (const Term& term : terms_) {
    const int i = term.index;
    e += term.vertex ? rod::VertexEnergy(edges_[i - 1], edges_[i], twist_near_[i], stiffness_, nullptr, nullptr,
                                         &twist_cache_[i])
                     : StretchEnergy(i, nullptr, nullptr);
  }
  frames_key_.Set(x, u);
  if (contact_.enabled()) e += contact_.Energy(ContactNodes(x, gm));
  energy_key_.Set(x, u);
  energy_cache_ = e;
  return e;
}

void RodModel::Gradient(const Vec& x, const Vec& u, Vec* g) const {
  if (g->size() != nx_) g->resize(nx_);
  g->setZero();
  const GraspMaps& gm = GraspDerivatives(u);
  PrepareEdges(x, u, gm, false, false);
  // The energy comes with the terms (Energy()'s sum in its order: the same bits) and is
  // kept: a solver asks for E at the state whose gradient it has just evaluated.
  double e = 0.0;
  for (int t = 0; t < static_cast<int>(terms_.size()); ++t) {
    const Term& term = terms_[t];
    if (term.first >= 0) {
      e += AddInteriorTerm(term, g->data(), nullptr, 0);
    } else {
      e += Local(t, gm, false, [&](const double* lg, const double*, int) { assembly_.AddGradient(t, lg, g->data()); });
    }
  }
  frames_key_.Set(x, u);
  if (contact_.enabled()) {
    contact_.AddGradient(ContactNodes(x, gm), g->data());
    return;  // its energy is a pass of its own: Energy() computes it when asked
  }
  energy_key_.Set(x, u);
  energy_cache_ = e;
}

void RodModel::Hessian(const Vec& x, const Vec& u, SparseMatrix* h) const {
  // StoreHessian: every elastic slot is reached by an elastic term first, so no clearing
  // pass; slots only a contact pair reaches are cleared when contact is on. The pattern
  // first covers the pairs active here (contact_terms.h).
  if (contact_.enabled()) contact_.CoverActive(ContactNodes(x, GraspDerivatives(u)));
  double* values = assembly_.Values(h, contact_.enabled());
  if (band_key_.Matches(x, u)) {
    // At the state of the last band (a solver that factorised it in place asks for the
    // compressed matrix there): its values, read back (the sign of a zero aside, model.h).
    const int b = assembly_.Bandwidth();
    const int* outer = h->outerIndexPtr();
    const int* inner = h->innerIndexPtr();
    for (int j = 0; j < nx_; ++j) {
      for (int k = outer[j]; k < outer[j + 1]; ++k) {
        const int r = std::max(inner[k], j), c = std::min(inner[k], j);
        values[k] = band_cache_[static_cast<size_t>(r) * (b + 1) + c - r + b];
      }
    }
    return;
  }
  const GraspMaps& gm = GraspDerivatives(u);
  PrepareEdges(x, u, gm, true, false);
  for (int t = 0; t < static_cast<int>(terms_.size()); ++t) {
    Local(t, gm, true, [&](const double*, const double* lh, int ld) { assembly_.StoreHessian(t, lh, ld, values); });
  }
  frames_key_.Set(x, u);
  if (contact_.enabled()) contact_.AddHessian(ContactNodes(x, gm), values);
}

void RodModel::GradientAndHessian(const Vec& x, const Vec& u, Vec* g, SparseMatrix* h) const {
  EnergyGradientAndHessian(x, u, g, h);
}

double RodModel::EnergyGradientAndHessian(const Vec& x, const Vec& u, Vec* g, SparseMatrix* h) const {
  if (g->size() != nx_) g->resize(nx_);
  g->setZero();
  const GraspMaps& gm = GraspDerivatives(u);
  if (contact_.enabled()) contact_.CoverActive(ContactNodes(x, gm));
  double* values = assembly_.Values(h, contact_.enabled());
  PrepareEdges(x, u, gm, true, false);
  double e = 0.0;
  for (int t = 0; t < static_cast<int>(terms_.size()); ++t) {
    e += Local(t, gm, true, [&](const double* lg, const double* lh, int ld) {
      assembly_.AddGradient(t, lg, g->data());
      assembly_.StoreHessian(t, lh, ld, values);
    });
  }
  frames_key_.Set(x, u);
  if (contact_.enabled()) {
    const Eigen::Matrix3Xd& nodes = ContactNodes(x, gm);
    contact_.AddGradient(nodes, g->data());
    contact_.AddHessian(nodes, values);
    e += contact_.Energy(nodes);
  }
  energy_key_.Set(x, u);
  energy_cache_ = e;
  return e;
}

bool RodModel::EnergyGradientAndBandHessian(const Vec& x, const Vec& u, Vec* g, double* band, int bandwidth,
                                            double* energy) const {
  if (contact_.enabled() || bandwidth != assembly_.Bandwidth()) return false;
  if (g->size() != nx_) g->resize(nx_);
  g->setZero();
  std::fill(band, band + static_cast<std::ptrdiff_t>(nx_) * (bandwidth + 1), 0.0);
  const GraspMaps& gm = GraspDerivatives(u);
  PrepareEdges(x, u, gm, true, false);
  double e = 0.0;
  for (int t = 0; t < static_cast<int>(terms_.size()); ++t) {
    const Term& term = terms_[t];
    if (term.first >= 0) {
      e += AddInteriorTerm(term, g->data(), band, bandwidth);
      continue;
    }
    e += Local(t, gm, true, [&](const double* lg, const double* lh, int ld) {
      assembly_.AddGradient(t, lg, g->data());
      assembly_.AddBandHessian(t, lh, ld, band);
    });
  }
  frames_key_.Set(x, u);
  *energy = e;
  energy_key_.Set(x, u);
  energy_cache_ = e;
  std::copy(band, band + band_cache_.size(), band_cache_.begin());
  band_key_.Set(x, u);
  return true;
}

void RodModel::ControlGradient(const Vec& x, const Vec& u, Vec* eu) const {
  if (eu->size() != nu_) eu->resize(nu_);
  eu->setZero();
  const GraspMaps& gm = GraspDerivatives(u);
  PrepareEdges(x, u, gm, false, true);
  for (int t : control_terms_) {
    Local(t, gm, false, [&](const double* lg, const double*, int) { assembly_.AddControlGradient(t, lg, eu->data()); });
  }
  if (contact_.enabled()) contact_.AddControlGradient(ContactNodes(x, gm), ContactControls(gm), eu->data());
}

void RodModel::GraspTorque(const Vec& x, const Vec& u, Eigen::Vector3d* torque) const {
  // The E_u of a grasp map differentiated in a world rotation δ instead of φ: the
  // rotation-vector gradient E_φ = J_l(φ)ᵀ E_δ loses the torque where J_l is singular
  // (|φ| = 2π, 4π: two turns of a roll).
  const GraspMaps gm = Grasp(u, true, true);
  frames_key_.valid = false;  // the edges at the grasp from another map (the same values, but not by contract)
  PrepareEdges(x, u, gm, false, true);
  Eigen::Matrix<double, 12, 1> e = Eigen::Matrix<double, 12, 1>::Zero();
  for (int t : control_terms_) {
    Local(t, gm, false, [&](const double* lg, const double*, int) { assembly_.AddControlGradient(t, lg, e.data()); });
  }
  if (contact_.enabled()) contact_.AddControlGradient(ContactNodes(x, gm), ContactControls(gm), e.data());
  *torque = -e.segment<3>(3);  // the first grasp's (edge 0's without a clamp)
}

void RodModel::MixedHessian(const Vec& x, const Vec& u, Mat* exu) const {
  if (exu->rows() != nx_ || exu->cols() != nu_) exu->resize(nx_, nu_);
  exu->setZero();
  const GraspMaps& gm = GraspDerivatives(u);
  PrepareEdges(x, u, gm, true, true);
  for (int t : control_terms_) {
    Local(t, gm, true, [&](const double*, const double* lh, int ld) { assembly_.AddMixedHessian(t, lh, ld, exu); });
  }
  if (contact_.enabled()) contact_.AddMixedHessian(ContactNodes(x, gm), ContactControls(gm), exu);
}

void RodModel::ControlHessian(const Vec& x, const Vec& u, Mat* euu) const {
  if (euu->rows() != nu_ || euu->cols() != nu_) euu->resize(nu_, nu_);
  euu->setZero();
  const GraspMaps& gm = GraspDerivatives(u);
  PrepareEdges(x, u, gm, true, true);
  for (int t : control_terms_) {
    Local(t, gm, true, [&](const double*, const double* lh, int ld) { assembly_.AddControlHessian(t, lh, ld, euu); });
  }
  if (contact_.enabled()) contact_.AddControlHessian(ContactNodes(x, gm), ContactControls(gm), euu);
}

void RodModel::ControlDerivatives(const Vec& x, const Vec& u, Vec* eu, Mat* exu, Mat* euu) const {
  if (eu->size() != nu_) eu->resize(nu_);
  if (exu->rows() != nx_ || exu->cols() != nu_) exu->resize(nx_, nu_);
  if (euu->rows() != nu_ || euu->cols() != nu_) euu->resize(nu_, nu_);
  eu->setZero();
  exu->setZero();
  euu->setZero();
  const GraspMaps& gm = GraspDerivatives(u);
  PrepareEdges(x, u, gm, true, true);
  for (int t : control_terms_) {
    Local(t, gm, true, [&](const double* lg, const double* lh, int ld) {
      assembly_.AddControlGradient(t, lg, eu->data());
      assembly_.AddMixedHessian(t, lh, ld, exu);
      assembly_.AddControlHessian(t, lh, ld, euu);
    });
  }
  if (contact_.enabled()) {
    const Eigen::Matrix3Xd& nodes = ContactNodes(x, gm);
    const internal::ControlMap map = ContactControls(gm);
    contact_.AddControlGradient(nodes, map, eu->data());
    contact_.AddMixedHessian(nodes, map, exu);
    contact_.AddControlHessian(nodes, map, euu);
  }
}

}  // namespace snapthread
