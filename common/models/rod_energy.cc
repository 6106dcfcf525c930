// Derivation of the vertex Hessian (rod_energy.h for the notation). For one edge j
// write p = m1·κb, q = m2·κb (κb ⊥ t_j, so t_j·κb ≡ 0 and t_j·dκb = -κb·de_j/|e_j|):
//   dq = -p dφ + m2·dκb,   dp = q dφ + m1·dκb,
//   d²q = -q dφ dφ - dφ (m1·dκb) - (m1·dκb) dφ - p B + (κb·de)(m2·de)/|e|² + m2·d²κb,
//   d²p = -p dφ dφ + dφ (m2·dκb) + (m2·dκb) dφ + q B + (κb·de)(m1·de)/|e|² + m1·d²κb,
// where B = ∂(Â/|e|)/∂e = (dÂ/dt)(I - t tᵀ)/|e|² - Â tᵀ/|e|² is the derivative of the
// twist-rate term of dφ. (The B and (κb·de)(m·de) terms are not symmetric one by one;
// their sum is, because the curl of Â is the area form of the sphere.) With
// E_bend = ¼ Σ_j [B1 (q_j - κ̄1)² + B2 (-p_j - κ̄2)²] / ℓ̄ the d²κb terms of all four
// directors are gathered into one contraction W·d²κb, W·κb = 2 W·(e0×e1)/χ,
// χ = |e0||e1| + e0·e1, differentiated as a quotient.
#include "models/rod_energy.h"

#include <cmath>

namespace snapthread::rod {
namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

// Hessian of W·κb with respect to (e0, e1) for a fixed vector W.
Mat6 ContractedCurvatureHessian(const V3& e0, const V3& e1, double l0, double l1, const V3& t0,
                                const V3& t1, double chi, const V3& w) {
  const double f = 2.0 * w.dot(e0.cross(e1)) / chi;
  Vec6 gn, gchi;
  gn << 2.0 * e1.cross(w), 2.0 * w.cross(e0);
  gchi << l1 * t0 + e1, l0 * t1 + e0;
  Mat6 hn = Mat6::Zero();
  hn.block<3, 3>(0, 3) = -2.0 * Cross(w);
  hn.block<3, 3>(3, 0) = 2.0 * Cross(w);
  Mat6 hchi;
  hchi.block<3, 3>(0, 0) = (l1 / l0) * (M3::Identity() - t0 * t0.transpose());
  hchi.block<3, 3>(3, 3) = (l0 / l1) * (M3::Identity() - t1 * t1.transpose());
  hchi.block<3, 3>(0, 3) = M3::Identity() + t0 * t1.transpose();
  hchi.block<3, 3>(3, 0) = M3::Identity() + t1 * t0.transpose();
  const Vec6 gf = (gn - f * gchi) / chi;
  return (hn - f * hchi - gchi * gf.transpose() - gf * gchi.transpose()) / chi;
}

}  // namespace

double ReferenceTwist(const V3& e0, const V3& e1, const FrameSource& s0, const FrameSource& s1,
                      double near) {
  const V3 t0 = e0.normalized(), t1 = e1.normalized();
  V3 a0, b0, a1, b1;
  ReferenceFrame(s0, t0, &a0, &b0);
  ReferenceFrame(s1, t1, &a1, &b1);
  return AngleAbout(t1, Transport(t0, t1, a0), a1, near);
}

double VertexEnergy(const V3& e0, const V3& e1, double theta0, double theta1,
                    const FrameSource& s0, const FrameSource& s1, double twist_near,
                    const VertexStiffness& k, Vec8* g, Mat8* h) {
  const V3 e[2] = {e0, e1};
  const FrameSource* src[2] = {&s0, &s1};
  const double th[2] = {theta0, theta1};
  double l[2];
  V3 t[2], a[2], m1[2], m2[2];
  for (int j = 0; j < 2; ++j) {
    l[j] = e[j].norm();
    t[j] = e[j] / l[j];
    V3 b;
    ReferenceFrame(*src[j], t[j], &a[j], &b);
    const double c = std::cos(th[j]), s = std::sin(th[j]);
    m1[j] = c * a[j] + s * b;
    m2[j] = -s * a[j] + c * b;
  }
  const double chi = l[0] * l[1] + e0.dot(e1);
  const V3 kb = (2.0 / chi) * e0.cross(e1);  // [DER (1)]
  // Material curvatures of each edge [DER §4.2]: κ^j = (κb·m2_j, -κb·m1_j).
  double r1[2], r2[2];
  double bend = 0.0;
  for (int j = 0; j < 2; ++j) {
    r1[j] = kb.dot(m2[j]) - k.kappa1_bar;
    r2[j] = -kb.dot(m1[j]) - k.kappa2_bar;
    bend += k.c1 * r1[j] * r1[j] + k.c2 * r2[j] * r2[j];
  }
  const double mref = AngleAbout(t[1], Transport(t[0], t[1], a[0]), a[1], twist_near);
  const double tau = theta1 - theta0 + mref;
  // Bending: the mean of the two edges' energies [DER (4)]; twist [DVT (4)].
  const double energy = 0.25 * bend + 0.5 * k.ct * tau * tau;
  if (g == nullptr && h == nullptr) return energy;

  // ∂κb/∂e0, ∂κb/∂e1 [DER §6]: (±2[e]× - κb ∇χᵀ)/χ.
  M3 jk[2];
  jk[0] = (-2.0 * Cross(e1) - kb * (l[1] * t[0] + e1).transpose()) / chi;
  jk[1] = (2.0 * Cross(e0) - kb * (l[0] * t[1] + e0).transpose()) / chi;
  Vec8 dphi[2], jm1[2], jm2[2], gq[2], gp[2];
  V3 alpha[2];
  double p[2], q[2];
  for (int j = 0; j < 2; ++j) {
    p[j] = m1[j].dot(kb);
    q[j] = m2[j].dot(kb);
    alpha[j] = TwistRate(src[j]->t, t[j]) / l[j];
    dphi[j].setZero();
    dphi[j].segment<3>(3 * j) = alpha[j];
    dphi[j][6 + j] = 1.0;
    jm1[j] << jk[0].transpose() * m1[j], jk[1].transpose() * m1[j], 0.0, 0.0;
    jm2[j] << jk[0].transpose() * m2[j], jk[1].transpose() * m2[j], 0.0, 0.0;
    gq[j] = -p[j] * dphi[j] + jm2[j];
    gp[j] = q[j] * dphi[j] + jm1[j];
  }
  Vec8 gtau;
  gtau << kb / (2.0 * l[0]) - alpha[0], kb / (2.0 * l[1]) + alpha[1], -1.0, 1.0;
  if (g != nullptr) {
    *g = k.ct * tau * gtau;
    for (int j = 0; j < 2; ++j) *g += 0.5 * (k.c1 * r1[j] * gq[j] - k.c2 * r2[j] * gp[j]);
  }
  if (h == nullptr) return energy;

  Mat8& hh = *h;
  hh = k.ct * gtau * gtau.transpose();
  M3 balpha[2];
  V3 w = V3::Zero();
  for (int j = 0; j < 2; ++j) {
    hh.noalias() += 0.5 * k.c1 * gq[j] * gq[j].transpose() + 0.5 * k.c2 * gp[j] * gp[j].transpose();
    const double wq = 0.5 * k.c1 * r1[j];   // weight of d²q_j in E
    const double wp = -0.5 * k.c2 * r2[j];  // weight of d²p_j in E
    w += wq * m2[j] + wp * m1[j];
    const double inv_l2 = 1.0 / (l[j] * l[j]);
    const M3 proj = M3::Identity() - t[j] * t[j].transpose();
    balpha[j] = (TwistRateJacobian(src[j]->t, t[j]) * proj - TwistRate(src[j]->t, t[j]) *
                 t[j].transpose()) * inv_l2;
    const Vec8 side = -wq * jm1[j] + wp * jm2[j];
    hh.noalias() -= (wq * q[j] + wp * p[j]) * dphi[j] * dphi[j].transpose();
    hh.noalias() += dphi[j] * side.transpose() + side * dphi[j].transpose();
    hh.block<3, 3>(3 * j, 3 * j) += (wp * q[j] - wq * p[j]) * balpha[j] +
                                    inv_l2 * kb * (wq * m2[j] + wp * m1[j]).transpose();
  }
  hh.topLeftCorner<6, 6>() += ContractedCurvatureHessian(e0, e1, l[0], l[1], t[0], t[1], chi, w);
  // Twist: ct τ ∇²m, from dm above.
  const double ct = k.ct * tau;
  for (int j = 0; j < 2; ++j) {
    for (int c = 0; c < 2; ++c) {
      hh.block<3, 3>(3 * j, 3 * c) += (ct / (2.0 * l[j])) * jk[c];
    }
    hh.block<3, 3>(3 * j, 3 * j) -= (ct / (2.0 * l[j] * l[j])) * kb * t[j].transpose();
  }
  hh.block<3, 3>(0, 0) -= ct * balpha[0];
  hh.block<3, 3>(3, 3) += ct * balpha[1];
  return energy;
}

}  // namespace snapthread::rod
