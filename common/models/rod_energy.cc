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

// Lower-triangle accumulation into a symmetric 8x8 (mirrored at the end): a sum's lower
// triangle is the sum of its pieces' lower triangles, symmetric pieces or not.
// s M into block (j, c) of the edge coordinates (j >= c; a diagonal block's lower part).
inline void LowerBlock(int j, int c, double s, const M3& m, Mat8* h) {
  for (int cc = 0; cc < 3; ++cc) {
    for (int rr = (j == c ? cc : 0); rr < 3; ++rr) (*h)(3 * j + rr, 3 * c + cc) += s * m(rr, cc);
  }
}

// VertexEnergy's intermediate values, shared by its steps (BendAndTwist, GradientParts,
// AddOuterProducts, AddEdgeBlocks): the curvature binormal κb over χ, each edge's
// material curvatures and their residuals, the total twist τ, and the first derivatives.
struct VertexParts {
  double chi = 0.0, inv_chi = 0.0, tau = 0.0, ct = 0.0;
  V3 kb;
  double p[2], q[2], r1[2], r2[2];
  V3 gchi[2];
  Vec8 dphi[2], gq[2], gp[2], jm1[2], jm2[2];
  Vec8 gtau;
};

// The energy: bending (the material curvatures p, q) and twist (τ).
double BendAndTwist(const EdgeFrame& f0, const EdgeFrame& f1, double twist_near, const VertexStiffness& k,
                    VertexParts* vp, double* reference_twist) {
  const EdgeFrame* f[2] = {&f0, &f1};
  const V3& e0 = f0.e;
  const V3& e1 = f1.e;
  vp->chi = f0.l * f1.l + e0.dot(e1);
  const double chi = vp->chi;
  vp->kb = (2.0 / chi) * e0.cross(e1);  // [DER (1)]
  const V3& kb = vp->kb;
  // Material curvatures of each edge [DER §4.2]: κ^j = (κb·m2_j, -κb·m1_j) = (q_j, -p_j).
  double(&p)[2] = vp->p;
  double(&q)[2] = vp->q;
  double(&r1)[2] = vp->r1;
  double(&r2)[2] = vp->r2;
  double bend = 0.0;
  for (int j = 0; j < 2; ++j) {
    p[j] = kb.dot(f[j]->m1);
    q[j] = kb.dot(f[j]->m2);
    r1[j] = q[j] - k.kappa1_bar;
    r2[j] = -p[j] - k.kappa2_bar;
    bend += k.c1 * r1[j] * r1[j] + k.c2 * r2[j] * r2[j];
  }
  const double mref = AngleAbout(f1.t, Transport(f0.t, f1.t, f0.a), f1.a, twist_near);
  if (reference_twist != nullptr) *reference_twist = mref;
  vp->tau = f1.theta - f0.theta + mref;
  const double tau = vp->tau;
  // Bending: the mean of the two edges' energies [DER (4)]; twist [DVT (4)].
  return 0.25 * bend + 0.5 * k.ct * tau * tau;
}

// The first derivatives of q, p and τ in the edge coordinates and angles.
void GradientParts(const EdgeFrame& f0, const EdgeFrame& f1, VertexParts* vp) {
  const EdgeFrame* f[2] = {&f0, &f1};
  const V3& e0 = f0.e;
  const V3& e1 = f1.e;
  const double(&p)[2] = vp->p;
  const double(&q)[2] = vp->q;
  // ∂κb/∂e_c = (±2[e_other]× - κb ∇χ_cᵀ)/χ [DER §6], ∇χ = (|e1| t0 + e1, |e0| t1 + e0);
  // applied transposed to a vector v: ((2 e1 × v, -2 e0 × v) - (κb·v) ∇χ)/χ.
  vp->inv_chi = 1.0 / vp->chi;
  const double inv_chi = vp->inv_chi;
  vp->gchi[0] = f1.l * f0.t + e1;
  vp->gchi[1] = f0.l * f1.t + e0;
  const V3(&gchi)[2] = vp->gchi;
  Vec8(&dphi)[2] = vp->dphi;
  Vec8(&gq)[2] = vp->gq;
  Vec8(&gp)[2] = vp->gp;
  Vec8(&jm1)[2] = vp->jm1;
  Vec8(&jm2)[2] = vp->jm2;
  for (int j = 0; j < 2; ++j) {
    const V3& m1 = f[j]->m1;
    const V3& m2 = f[j]->m2;
    jm1[j] << (2.0 * e1.cross(m1) - p[j] * gchi[0]) * inv_chi, (-2.0 * e0.cross(m1) - p[j] * gchi[1]) * inv_chi,
        0.0, 0.0;
    jm2[j] << (2.0 * e1.cross(m2) - q[j] * gchi[0]) * inv_chi, (-2.0 * e0.cross(m2) - q[j] * gchi[1]) * inv_chi,
        0.0, 0.0;
    dphi[j].setZero();
    dphi[j].segment<3>(3 * j) = f[j]->alpha;
    dphi[j][6 + j] = 1.0;
    gq[j] = jm2[j] - p[j] * dphi[j];
    gp[j] = jm1[j] + q[j] * dphi[j];
  }
  vp->gtau << vp->kb / (2.0 * f0.l) - f0.alpha, vp->kb / (2.0 * f1.l) + f1.alpha, -1.0, 1.0;
}

// The Hessian's outer products and diagonal blocks into *h (lower triangle; zeroed
// first); returns W, the weight of the d²κb contraction (AddEdgeBlocks).
V3 AddOuterProducts(const EdgeFrame& f0, const EdgeFrame& f1, const VertexStiffness& k, VertexParts* vp, Mat8* h) {
  const EdgeFrame* f[2] = {&f0, &f1};
  const V3& kb = vp->kb;
  const double(&p)[2] = vp->p;
  const double(&q)[2] = vp->q;
  const double(&r1)[2] = vp->r1;
  const double(&r2)[2] = vp->r2;
  const Vec8(&dphi)[2] = vp->dphi;
  const Vec8(&gq)[2] = vp->gq;
  const Vec8(&gp)[2] = vp->gp;
  const Vec8(&jm1)[2] = vp->jm1;
  const Vec8(&jm2)[2] = vp->jm2;
  const Vec8& gtau = vp->gtau;
  // The lower triangle of every piece (rod_energy.cc's header for the derivation), then
  // the mirror.
  Mat8& hh = *h;
  hh.setZero();
  vp->ct = k.ct * vp->tau;
  const double ct = vp->ct;
  V3 w = V3::Zero();
  Vec8 v[2];
  M3 blk[2];
  for (int j = 0; j < 2; ++j) {
    const EdgeFrame& fj = *f[j];
    const double wq = 0.5 * k.c1 * r1[j];   // weight of d²q_j in E
    const double wp = -0.5 * k.c2 * r2[j];  // weight of d²p_j in E
    w += wq * fj.m2 + wp * fj.m1;
    // -(wq q + wp p) dφ dφᵀ + dφ sideᵀ + side dφᵀ = dφ vᵀ + v dφᵀ, v = side - ½(wq q + wp p) dφ.
    v[j] = wp * jm2[j] - wq * jm1[j] - (0.5 * (wq * q[j] + wp * p[j])) * dphi[j];
    // Block (j, j): the twist-rate derivative (bending and twist) and the (κb·de)(m·de)/|e|²
    // terms with the twist's -ct κb tᵀ/(2|e|²).
    const double inv_l2 = 1.0 / (fj.l * fj.l);
    blk[j] = (wp * q[j] - wq * p[j] + (j == 0 ? -ct : ct)) * fj.dalpha +
             inv_l2 * kb * (wq * fj.m2 + wp * fj.m1 - (0.5 * ct) * fj.t).transpose();
  }
  // The outer products GJ gτ gτᵀ + Σ_j [½B1 gq_j gq_jᵀ + ½B2 gp_j gp_jᵀ + dφ_j v_jᵀ + v_j dφ_jᵀ]
  // in one pass over each column, from the even row at or above the diagonal (whole,
  // aligned packets; what lands above it is overwritten by the mirror). Each entry is
  // summed in the order of the terms (j = 0's, block (0, 0) of j = 0, j = 1's, block
  // (1, 1) of j = 1, then the rest): the sums of the terms added one at a time, to the bit.
  const double b1 = 0.5 * k.c1, b2 = 0.5 * k.c2;
  auto edge0 = [&]<int R, int N>(int c) __attribute__((always_inline)) {  // j = 0's terms
    auto x = hh.col(c).template segment<N>(R);
    x = x + (k.ct * gtau[c]) * gtau.template segment<N>(R) + (b1 * gq[0][c]) * gq[0].template segment<N>(R) +
        (b2 * gp[0][c]) * gp[0].template segment<N>(R) +
        (v[0][c] * dphi[0].template segment<N>(R) + dphi[0][c] * v[0].template segment<N>(R));
  };
  auto edge1 = [&]<int R, int N>(int c) __attribute__((always_inline)) {  // j = 1's terms
    auto x = hh.col(c).template segment<N>(R);
    x = x + (b1 * gq[1][c]) * gq[1].template segment<N>(R) + (b2 * gp[1][c]) * gp[1].template segment<N>(R) +
        (v[1][c] * dphi[1].template segment<N>(R) + dphi[1][c] * v[1].template segment<N>(R));
  };
  auto both = [&]<int R, int N>(int c) __attribute__((always_inline)) {
    auto x = hh.col(c).template segment<N>(R);
    x = x + (k.ct * gtau[c]) * gtau.template segment<N>(R) + (b1 * gq[0][c]) * gq[0].template segment<N>(R) +
        (b2 * gp[0][c]) * gp[0].template segment<N>(R) +
        (v[0][c] * dphi[0].template segment<N>(R) + dphi[0][c] * v[0].template segment<N>(R)) +
        (b1 * gq[1][c]) * gq[1].template segment<N>(R) + (b2 * gp[1][c]) * gp[1].template segment<N>(R) +
        (v[1][c] * dphi[1].template segment<N>(R) + dphi[1][c] * v[1].template segment<N>(R));
  };
  // Columns 0..2: block (0, 0) (rows 0..2, and row 3 with them) takes blk[0] between.
  edge0.template operator()<0, 4>(0);
  edge0.template operator()<0, 4>(1);
  edge0.template operator()<2, 2>(2);
  LowerBlock(0, 0, 1.0, blk[0], &hh);
  edge1.template operator()<0, 4>(0);
  edge1.template operator()<0, 4>(1);
  edge1.template operator()<2, 2>(2);
  both.template operator()<4, 4>(0);
  both.template operator()<4, 4>(1);
  both.template operator()<4, 4>(2);
  both.template operator()<2, 6>(3);
  both.template operator()<4, 4>(4);
  both.template operator()<4, 4>(5);
  both.template operator()<6, 2>(6);
  both.template operator()<6, 2>(7);
  LowerBlock(1, 1, 1.0, blk[1], &hh);
  return w;
}

// The Hessian's 3x3 edge blocks (lower triangle).
void AddEdgeBlocks(const EdgeFrame& f0, const EdgeFrame& f1, const VertexParts& vp, const V3& w, Mat8* h) {
  const V3& e0 = f0.e;
  const V3& e1 = f1.e;
  const V3& kb = vp.kb;
  const V3(&gchi)[2] = vp.gchi;
  const double inv_chi = vp.inv_chi;
  const double ct = vp.ct;
  Mat8& hh = *h;
  // The 3x3 edge blocks (0, 0), (1, 0), (1, 1), entry by entry in the order of the terms:
  //  * twist: ct ∂(κb/(2|e_j|))/∂e_c;
  //  * W·d²κb for W = w: the Hessian of W·κb = W·(2 e0 × e1)/χ as a quotient,
  //    (hn - f hchi - gχ gfᵀ - gf gχᵀ)/χ with f = W·κb, gf = (gn - f gχ)/χ: first
  //    -(gχ gfᵀ + gf gχᵀ)/χ, then hn, block (1, 0) = 2[W]×, and -f hchi, the diagonal
  //    blocks (|e_o|/|e_j|)(I - t tᵀ) and (1, 0) = I + t1 t0ᵀ.
  const M3 jk0 = (-2.0 * Cross(e1) - kb * gchi[0].transpose()) * inv_chi;
  const M3 jk1 = (2.0 * Cross(e0) - kb * gchi[1].transpose()) * inv_chi;
  const double fw = w.dot(kb);
  Eigen::Matrix<double, 6, 1> gc, gf;
  gc << gchi[0], gchi[1];
  gf << 2.0 * e1.cross(w), 2.0 * w.cross(e0);
  gf = (gf - fw * gc) * inv_chi;
  const double s = fw * inv_chi;
  const M3 cw = Cross(w);
  const M3 p10 = M3::Identity() + f1.t * f0.t.transpose();
  const M3 p00 = M3::Identity() - f0.t * f0.t.transpose();
  const M3 p11 = M3::Identity() - f1.t * f1.t.transpose();
  const double t00 = ct / (2.0 * f0.l), t10 = ct / (2.0 * f1.l), t11 = ct / (2.0 * f1.l);
  const double c10 = 2.0 * inv_chi, s10 = -s, s00 = -s * f1.l / f0.l, s11 = -s * f0.l / f1.l;
  auto quotient = [&](int r, int c) __attribute__((always_inline)) { return (gc[r] * gf[c] + gf[r] * gc[c]) * inv_chi; };
  for (int cc = 0; cc < 3; ++cc) {
    for (int rr = cc; rr < 3; ++rr) {
      double& x = hh(rr, cc);
      x += t00 * jk0(rr, cc);
      x -= quotient(rr, cc);
      x += s00 * p00(rr, cc);
    }
    for (int rr = 0; rr < 3; ++rr) {
      double& x = hh(3 + rr, cc);
      x += t10 * jk0(rr, cc);
      x -= quotient(3 + rr, cc);
      x += c10 * cw(rr, cc);
      x += s10 * p10(rr, cc);
    }
    for (int rr = cc; rr < 3; ++rr) {
      double& x = hh(3 + rr, 3 + cc);
      x += t11 * jk1(rr, cc);
      x -= quotient(3 + rr, 3 + cc);
      x += s11 * p11(rr, cc);
    }
  }
}

}  // namespace

void ComputeEdgeFrame(const V3& e, double theta, const FrameSource& s, bool want_h, EdgeFrame* f) {
  f->e = e;
  f->theta = theta;
  f->l = e.norm();
  f->t = e / f->l;
  V3 b;
  ReferenceFrame(s, f->t, &f->a, &b);
  const double c = std::cos(theta), sn = std::sin(theta);
  f->m1 = c * f->a + sn * b;
  f->m2 = -sn * f->a + c * b;
  const double inv_l = 1.0 / f->l;
  const double den = 1.0 / (1.0 + s.t.dot(f->t));
  const V3 ahat = f->t.cross(s.t) * den;  // Â (TwistRate)
  f->alpha = ahat * inv_l;
  if (want_h) {
    // (dÂ/dt)(I - t tᵀ) - Â tᵀ, dÂ/dt = -([t_s]× + Â t_sᵀ)/(1 + t_s·t) (TwistRateJacobian).
    const M3 da = -(Cross(s.t) + ahat * s.t.transpose()) * den;
    f->dalpha = (da - (da * f->t + ahat) * f->t.transpose()) * (inv_l * inv_l);
  }
}

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
  EdgeFrame f0, f1;
  ComputeEdgeFrame(e0, theta0, s0, h != nullptr, &f0);
  ComputeEdgeFrame(e1, theta1, s1, h != nullptr, &f1);
  return VertexEnergy(f0, f1, twist_near, k, g, h);
}

double VertexEnergy(const EdgeFrame& f0, const EdgeFrame& f1, double twist_near,
                    const VertexStiffness& k, Vec8* g, Mat8* h, double* reference_twist) {
  VertexParts vp;
  const double energy = BendAndTwist(f0, f1, twist_near, k, &vp, reference_twist);
  if (g == nullptr && h == nullptr) return energy;

  GradientParts(f0, f1, &vp);
  const double tau = vp.tau;
  const double(&r1)[2] = vp.r1;
  const double(&r2)[2] = vp.r2;
  const Vec8(&gq)[2] = vp.gq;
  const Vec8(&gp)[2] = vp.gp;
  const Vec8& gtau = vp.gtau;
  if (g != nullptr) {
    *g = k.ct * tau * gtau;
    for (int j = 0; j < 2; ++j) *g += 0.5 * (k.c1 * r1[j] * gq[j] - k.c2 * r2[j] * gp[j]);
  }
  if (h == nullptr) return energy;

  const V3 w = AddOuterProducts(f0, f1, k, &vp, h);
  AddEdgeBlocks(f0, f1, vp, w, h);
  Mat8& hh = *h;
  for (int c = 0; c < 8; ++c) {
    for (int r = c + 1; r < 8; ++r) hh(c, r) = hh(r, c);
  }
  return energy;
}

}  // namespace snapthread::rod
