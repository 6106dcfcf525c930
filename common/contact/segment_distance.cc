#include "contact/segment_distance.h"

#include <algorithm>

namespace snapthread::contact {
namespace {

// Relative |ea × eb|² below which the segments count as parallel (see the header).
constexpr double kParallel = 1e-12;

// min over t in [0, 1] of |p - (b0 + t eb)|²: t and whether it is inside (0, 1).
double PointSegment(const V3& p, const V3& b0, const V3& eb, double ebb, double* t, bool* free) {
  double tt = 0.0;
  if (ebb > 0.0) tt = std::clamp((p - b0).dot(eb) / ebb, 0.0, 1.0);
  *t = tt;
  *free = tt > 0.0 && tt < 1.0;
  return (p - b0 - tt * eb).squaredNorm();
}

}  // namespace

SegmentClosest ClosestPoints(const V3& a0, const V3& a1, const V3& b0, const V3& b1) {
  const V3 ea = a1 - a0, eb = b1 - b0, r0 = a0 - b0;
  const double aa = ea.squaredNorm(), ab = ea.dot(eb), bb = eb.squaredNorm();
  const double denom = aa * bb - ab * ab;
  SegmentClosest c;
  if (denom > kParallel * aa * bb && denom > 0.0) {
    const double d = ea.dot(r0), e = eb.dot(r0);
    const double s = (ab * e - bb * d) / denom;
    const double t = (aa * e - ab * d) / denom;
    if (s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0) {
      c.s = s;
      c.t = t;
      c.s_free = c.t_free = true;
      c.distance_sq = (r0 + s * ea - t * eb).squaredNorm();
      return c;
    }
  }
  // On the square's boundary: each endpoint of one segment against the other segment.
  double best = -1.0;
  auto consider = [&](double dsq, double s, bool s_free, double t, bool t_free) {
    if (best >= 0.0 && !(dsq < best)) return;
    best = dsq;
    c = SegmentClosest{s, t, s_free, t_free, dsq};
  };
  double p;
  bool f;
  for (double s : {0.0, 1.0}) {
    const double dsq = PointSegment(a0 + s * ea, b0, eb, bb, &p, &f);
    consider(dsq, s, false, p, f);
  }
  for (double t : {0.0, 1.0}) {
    const double dsq = PointSegment(b0 + t * eb, a0, ea, aa, &p, &f);
    consider(dsq, p, f, t, false);
  }
  return c;
}

double SegmentDistanceSq(const V3& a0, const V3& a1, const V3& b0, const V3& b1, Vec12* g,
                         Mat12* h, SegmentClosest* closest) {
  const SegmentClosest c = ClosestPoints(a0, a1, b0, b1);
  if (closest != nullptr) *closest = c;
  if (g != nullptr || h != nullptr) SegmentDistanceDerivatives(a0, a1, b0, b1, c, g, h);
  return c.distance_sq;
}

void SegmentDistanceDerivatives(const V3& a0, const V3& a1, const V3& b0, const V3& b1,
                                const SegmentClosest& c, Vec12* g, Mat12* h) {
  const V3 ea = a1 - a0, eb = b1 - b0;
  const V3 r = a0 + c.s * ea - b0 - c.t * eb;
  // r = J x with J = [(1-s) I, s I, -(1-t) I, -t I]: coefficient of each endpoint.
  const double coef[4] = {1.0 - c.s, c.s, -(1.0 - c.t), -c.t};
  if (g != nullptr) {
    for (int k = 0; k < 4; ++k) g->segment<3>(3 * k) = (2.0 * coef[k]) * r;  // f_x = 2 Jᵀ r
  }
  if (h == nullptr) return;
  // f_xx = 2 JᵀJ.
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      h->block<3, 3>(3 * i, 3 * j) = (2.0 * coef[i] * coef[j]) * Eigen::Matrix3d::Identity();
    }
  }
  // f_xs = 2 Jᵀ ea + 2 (-r, r, 0, 0), f_xt = -2 Jᵀ eb + 2 (0, 0, r, -r);
  // f_ss = 2 ea·ea, f_tt = 2 eb·eb, f_st = -2 ea·eb.
  Vec12 fxs, fxt;
  for (int k = 0; k < 4; ++k) {
    fxs.segment<3>(3 * k) = (2.0 * coef[k]) * ea;
    fxt.segment<3>(3 * k) = (-2.0 * coef[k]) * eb;
  }
  fxs.segment<3>(0) -= 2.0 * r;
  fxs.segment<3>(3) += 2.0 * r;
  fxt.segment<3>(6) += 2.0 * r;
  fxt.segment<3>(9) -= 2.0 * r;
  const double fss = 2.0 * ea.squaredNorm(), ftt = 2.0 * eb.squaredNorm(), fst = -2.0 * ea.dot(eb);
  // D_xx = f_xx - f_xy f_yy⁻¹ f_yx over the free parameters y.
  if (c.s_free && c.t_free) {
    const double det = fss * ftt - fst * fst;
    const double iss = ftt / det, itt = fss / det, ist = -fst / det;
    h->noalias() -= iss * fxs * fxs.transpose() + itt * fxt * fxt.transpose() +
                    ist * (fxs * fxt.transpose() + fxt * fxs.transpose());
  } else if (c.s_free) {
    h->noalias() -= (1.0 / fss) * fxs * fxs.transpose();
  } else if (c.t_free) {
    h->noalias() -= (1.0 / ftt) * fxt * fxt.transpose();
  }
}

}  // namespace snapthread::contact
