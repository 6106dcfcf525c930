// Squared distance between two segments A = (a0, a1) and B = (b0, b1) in space, with
// its exact gradient and Hessian in the 12 endpoint coordinates x = (a0, a1, b0, b1).
//
// D(x) = min over (s, t) in [0, 1]² of f(x, s, t) = |r|², r = a0 + s ea - b0 - t eb,
// ea = a1 - a0, eb = b1 - b0. f is a convex quadratic in (s, t), so the minimiser is the
// unconstrained one when that lies inside the square, else it lies on an edge of the
// square (one of the four endpoint-to-segment problems, or an endpoint pair). Which of
// s, t are free at the minimiser is the case of IPC (Li et al. 2020, §4 and its
// supplement): both free (interior-interior, the edge-edge case), one free
// (endpoint-edge), none (endpoint-endpoint).
//
// Derivatives: by the envelope theorem D_x = f_x at the minimiser, and with y the free
// parameters (f_y = 0 there) the implicit function theorem gives
//   D_xx = f_xx - f_xy f_yy⁻¹ f_yx,
// exact wherever the case does not change (the gradient is continuous across cases).
//
// Parallel segments: f_ss f_tt - f_st² = 4 |ea × eb|² vanishes and the interior
// minimiser is not unique. Then (and when nearly so: |ea × eb|² ≤ 1e-12 |ea|² |eb|²)
// the interior case is not used; the minimum over the square's edges equals the minimum
// over the square for parallel segments, and differs from it by O(1e-12 |ea|² |eb|²)
// otherwise, so the distance stays continuous and every case has f_yy invertible.
#pragma once

#include <Eigen/Core>

namespace snapthread::contact {

using V3 = Eigen::Vector3d;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

struct SegmentClosest {
  double s = 0.0;  // parameter of the closest point on A (a0 + s ea)
  double t = 0.0;  // on B
  bool s_free = false;  // s strictly inside (0, 1): a free parameter of the case
  bool t_free = false;
  double distance_sq = 0.0;
};

// The closest points of the two segments (no derivatives).
SegmentClosest ClosestPoints(const V3& a0, const V3& a1, const V3& b0, const V3& b1);

// D = |p(s) - q(t)|² at the minimiser; g, h (may be null) its gradient and Hessian in
// (a0, a1, b0, b1).
double SegmentDistanceSq(const V3& a0, const V3& a1, const V3& b0, const V3& b1, Vec12* g,
                         Mat12* h, SegmentClosest* closest = nullptr);
// The same derivatives from the closest points ClosestPoints() found for these segments
// (a narrow phase that tests the distance first differentiates only the pairs it keeps).
void SegmentDistanceDerivatives(const V3& a0, const V3& a1, const V3& b0, const V3& b1,
                                const SegmentClosest& c, Vec12* g, Mat12* h);

}  // namespace snapthread::contact
