// A 3D chain's interior terms written straight into E_x and band storage
// (thread3d_model.cc's EnergyGradientAndBandHessian): the derivatives of StretchTerm<3>
// and BendTerm<3> (chain_terms.h) of a term whose variables are the consecutive
// states v0, v0 + 1, ..., from the unit segment directions and inverse lengths the caller
// computed once per segment, the lower triangle only.
#pragma once

#include <cstddef>

namespace snapthread::internal {

// The interior terms' derivatives, written into E_x and the band (banded_ldlt.h's layout)
// at their first state v0: A(v0 + r, v0 + q), r >= q, is base[r b + q] with
// base = band + v0 (b + 1) + b. Each entry is computed by the operations Eigen performs
// for StretchTerm's and BendTerm's expressions (chain_terms.h), in their order (Eigen
// evaluates a scalar times an outer product, k (p q^T), as (k p) q^T), so E_xx and E_x
// are Hessian()'s and Gradient()'s to the last bit. The inputs are copied into locals
// first and every result is computed before the first store, so the compiler keeps them
// in registers (the stores cannot alias them). Returns the term's energy.

// StretchTerm<3>, (3.7): H = 2c [(L/l) w w^T + (1 - L/l) I], node blocks [[H, -H], [-H, H]].
inline double StretchIntoBand(const double* w_in, double l, double inv, double c, double rest, int v0,
                              double* __restrict gd, double* __restrict band, int b) {
  const double w[3] = {w_in[0], w_in[1], w_in[2]};
  const double dl = l - rest;
  const double kg = 2.0 * c * dl;
  const double ratio = rest * inv;
  const double kh = 2.0 * c * ratio;
  const double kd = 2.0 * c * (1.0 - ratio);
  double gv[3], hv[3][3];  // hv[r][q] = H(r, q)
#pragma GCC unroll 3
  for (int r = 0; r < 3; ++r) {
    gv[r] = kg * w[r];
#pragma GCC unroll 3
    for (int q = 0; q < 3; ++q) hv[r][q] = (kh * w[r]) * w[q];
    hv[r][r] += kd;
  }
  double* g = gd + v0;
  double* base = band + static_cast<std::ptrdiff_t>(v0) * (b + 1) + b;
#pragma GCC unroll 3
  for (int r = 0; r < 3; ++r) {
    g[r] += -gv[r];
    g[3 + r] += gv[r];
    double* top = base + r * b;             // row v0 + r
    double* bottom = base + (3 + r) * b;    // row v0 + 3 + r
#pragma GCC unroll 3
    for (int q = 0; q <= r; ++q) {
      top[q] += hv[r][q];
      bottom[3 + q] += hv[r][q];
    }
#pragma GCC unroll 3
    for (int q = 0; q < 3; ++q) bottom[q] -= hv[r][q];  // += -H: the same bits
  }
  return c * dl * dl;
}

// BendTerm<3>, (3.6), with v1, v2 the segments before and after the joint: the blocks h11,
// h12 (h21 = h12^T), h22 of its comment, then the node blocks on and below the diagonal:
// (0,0) h11, (1,0) h21 - h11, (1,1) h11 - h12 - h21 + h22, (2,0) -h21, (2,1) h21 - h22,
// (2,2) h22. cth = w1 . w2 as Eigen computes it.
inline double BendIntoBand(const double* w1_in, double inv1, const double* w2_in, double inv2, double cth,
                           double c, int v0, double* __restrict gd, double* __restrict band, int b) {
  const double w1[3] = {w1_in[0], w1_in[1], w1_in[2]};
  const double w2[3] = {w2_in[0], w2_in[1], w2_in[2]};
  double a[3], bb[3];
#pragma GCC unroll 3
  for (int k = 0; k < 3; ++k) {
    a[k] = (w2[k] - cth * w1[k]) * inv1;
    bb[k] = (w1[k] - cth * w2[k]) * inv2;
  }
  const double c11 = c * cth * inv1 * inv1;
  const double c22 = c * cth * inv2 * inv2;
  const double k11 = c * inv1, k22 = c * inv2;
  const double s12 = -c * inv1 * inv2;
  // h11 and h22 are symmetric to the last bit (w1_r a_q + w1_q a_r and w1_r w1_q do not
  // depend on the order of r and q); h12 is not.
  double h11[3][3], h22[3][3], h12[3][3];
#pragma GCC unroll 3
  for (int r = 0; r < 3; ++r) {
#pragma GCC unroll 3
    for (int q = 0; q < 3; ++q) {
      const double p11 = w1[r] * w1[q], p22 = w2[r] * w2[q];
      h11[r][q] = k11 * (w1[r] * a[q] + w1[q] * a[r]) - c11 * p11;
      h22[r][q] = k22 * (w2[r] * bb[q] + w2[q] * bb[r]) - c22 * p22;
      h12[r][q] = s12 * ((cth * w1[r]) * w2[q] - p11 - p22);
    }
    h11[r][r] += c11;
    h22[r][r] += c22;
    h12[r][r] += s12;
  }
  double* g = gd + v0;
  double* base = band + static_cast<std::ptrdiff_t>(v0) * (b + 1) + b;
#pragma GCC unroll 3
  for (int r = 0; r < 3; ++r) {
    g[r] += c * a[r];
    g[3 + r] += -c * a[r] + c * bb[r];
    g[6 + r] += -c * bb[r];
    double* r0 = base + r * b;
    double* r1 = base + (3 + r) * b;
    double* r2 = base + (6 + r) * b;
#pragma GCC unroll 3
    for (int q = 0; q <= r; ++q) {
      r0[q] += h11[r][q];
      r1[3 + q] += h11[r][q] - h12[r][q] - h12[q][r] + h22[r][q];
      r2[6 + q] += h22[r][q];
    }
#pragma GCC unroll 3
    for (int q = 0; q < 3; ++q) {
      r1[q] += h12[q][r] - h11[r][q];
      r2[q] -= h12[q][r];  // += -h21: the same bits
      r2[3 + q] += h12[q][r] - h22[r][q];
    }
  }
  return c * (1.0 - cth);
}

}  // namespace snapthread::internal
