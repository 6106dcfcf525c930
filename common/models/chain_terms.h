// Closed-form per-term derivatives of the chain energies (curve2d, thread3d), in the
// coordinates of the term's nodes (D = 2 or 3); HessianAssembly (hessian_assembly.h) adds
// them into the global E_x, E_xx.
#pragma once

#include <Eigen/Core>

namespace snapthread::internal {

template <int D>
using NodeVec = Eigen::Matrix<double, D, 1>;

// Stretching c (|v| - rest)^2 of the segment v = p_b - p_a ((2.2); thread3d (3.7) with
// c = gamma/2). Local variables (p_a, p_b). Returns the energy; g/h may be null.
//   d/dv  = 2c (l - rest) w,                    w = v / l
//   d2/dv2 = 2c [ (rest/l) w w^T + (1 - rest/l) I ]
// and the node blocks follow from v = p_b - p_a: [[H, -H], [-H, H]].
template <int D>
inline double StretchTerm(const NodeVec<D>& pa, const NodeVec<D>& pb, double c, double rest,
                          Eigen::Matrix<double, 2 * D, 1>* g,
                          Eigen::Matrix<double, 2 * D, 2 * D>* h) {
  const NodeVec<D> v = pb - pa;
  const double l = v.norm();
  const double dl = l - rest;
  if (g != nullptr || h != nullptr) {
    // Reciprocals once: divisions cost several times a multiplication here.
    const double inv_l = 1.0 / l;
    const NodeVec<D> w = v * inv_l;
    if (g != nullptr) {
      const NodeVec<D> gv = (2.0 * c * dl) * w;
      g->template head<D>() = -gv;
      g->template tail<D>() = gv;
    }
    if (h != nullptr) {
      const double ratio = rest * inv_l;
      Eigen::Matrix<double, D, D> hv = (2.0 * c * ratio) * (w * w.transpose());
      hv.diagonal().array() += 2.0 * c * (1.0 - ratio);
      h->template topLeftCorner<D, D>() = hv;
      h->template topRightCorner<D, D>() = -hv;
      h->template bottomLeftCorner<D, D>() = -hv;
      h->template bottomRightCorner<D, D>() = hv;
    }
  }
  return c * dl * dl;
}

// Bending c (1 - w1.w2) at the joint between v1 = p_b - p_a and v2 = p_c - p_b
// ((2.2) with c = beta; thread3d (3.6) with c = beta/2). Local variables (p_a, p_b, p_c).
// With cth = w1.w2, a = (w2 - cth w1)/l1 = d cth/d v1, b = (w1 - cth w2)/l2 = d cth/d v2:
//   d/dv1 = -c a,  d/dv2 = -c b,
//   d2/dv1^2  =  c [ (w1 a^T + a w1^T)/l1 + cth (I - w1 w1^T)/l1^2 ]
//   d2/dv1dv2 = -c [ I - w1 w1^T - w2 w2^T + cth w1 w2^T ] / (l1 l2)
//   d2/dv2^2  =  c [ (w2 b^T + b w2^T)/l2 + cth (I - w2 w2^T)/l2^2 ]
// and the node blocks follow from the chain rule through v1 = p_b - p_a, v2 = p_c - p_b.
template <int D>
inline double BendTerm(const NodeVec<D>& pa, const NodeVec<D>& pb, const NodeVec<D>& pc,
                       double c, Eigen::Matrix<double, 3 * D, 1>* g,
                       Eigen::Matrix<double, 3 * D, 3 * D>* h) {
  using M = Eigen::Matrix<double, D, D>;
  const NodeVec<D> v1 = pb - pa;
  const NodeVec<D> v2 = pc - pb;
  // Reciprocals once: divisions cost several times a multiplication here.
  const double inv1 = 1.0 / v1.norm();
  const double inv2 = 1.0 / v2.norm();
  const NodeVec<D> w1 = v1 * inv1;
  const NodeVec<D> w2 = v2 * inv2;
  const double cth = w1.dot(w2);
  if (g != nullptr || h != nullptr) {
    const NodeVec<D> a = (w2 - cth * w1) * inv1;
    const NodeVec<D> b = (w1 - cth * w2) * inv2;
    if (g != nullptr) {
      g->template segment<D>(0) = c * a;
      g->template segment<D>(D) = -c * a + c * b;
      g->template segment<D>(2 * D) = -c * b;
    }
    if (h != nullptr) {
      const M w1w1 = w1 * w1.transpose();
      const M w2w2 = w2 * w2.transpose();
      const M wa = w1 * a.transpose();
      const M wb = w2 * b.transpose();
      const double c11 = c * cth * inv1 * inv1;
      const double c22 = c * cth * inv2 * inv2;
      M h11 = (c * inv1) * (wa + wa.transpose()) - c11 * w1w1;
      h11.diagonal().array() += c11;
      M h22 = (c * inv2) * (wb + wb.transpose()) - c22 * w2w2;
      h22.diagonal().array() += c22;
      const double s12 = -c * inv1 * inv2;
      M h12 = s12 * (cth * (w1 * w2.transpose()) - w1w1 - w2w2);
      h12.diagonal().array() += s12;
      // Jacobian of (v1, v2) w.r.t. (p_a, p_b, p_c): v1 = [-I, I, 0], v2 = [0, -I, I].
      const M h21 = h12.transpose();
      h->template block<D, D>(0, 0) = h11;
      h->template block<D, D>(0, D) = h12 - h11;
      h->template block<D, D>(0, 2 * D) = -h12;
      h->template block<D, D>(D, 0) = h21 - h11;
      h->template block<D, D>(D, D) = h11 - h12 - h21 + h22;
      h->template block<D, D>(D, 2 * D) = h12 - h22;
      h->template block<D, D>(2 * D, 0) = -h21;
      h->template block<D, D>(2 * D, D) = h21 - h22;
      h->template block<D, D>(2 * D, 2 * D) = h22;
    }
  }
  return c * (1.0 - cth);
}

}  // namespace snapthread::internal
