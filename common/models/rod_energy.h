// Bending and twisting energy of one interior vertex of the discrete elastic rod, with
// its exact gradient and Hessian (Bergou et al. 2008 "Discrete Elastic Rods" = [DER],
// Bergou et al. 2010 "Discrete Viscous Threads" = [DVT]).
//
// Local variables z = (e0, e1, θ0, θ1): the two edge vectors meeting at the vertex and
// their material angles against the time-parallel reference frames (rod_frames.h).
//   κb  = 2 e0 × e1 / (|e0||e1| + e0·e1)                         [DER (1)]
//   m1_j = cos θ_j a_j + sin θ_j b_j,  m2_j = -sin θ_j a_j + cos θ_j b_j   [DER §4.2]
//   κ^j = (κ1^j, κ2^j) = (κb·m2_j, -κb·m1_j), j = 0, 1                [DER §4.2]
//   m   = reference twist: the angle from P_{t0}^{t1} a_0 to a_1 about t1  [DVT §5.1]
//   τ   = θ1 - θ0 + m                                              [DVT (2)]
//   E   = ½ Σ_j ½ [B1 (κ1^j - κ̄1)² + B2 (κ2^j - κ̄2)²] / ℓ̄ + ½ GJ τ² / ℓ̄  [DER (4); DVT (4)]
// with ℓ̄ the rest Voronoi length (½ the two rest edge lengths).
//
// Why the material curvatures of each edge ([DER 2008], energy averaged over the two
// edges) and not the curvature of the averaged directors ½(m_0 + m_1)·κb [DVT]: for a
// round rod (B1 = B2) the former does not depend on the material angles at all, as in
// the continuum; the averaged directors shrink by cos(Δθ/2) when neighbouring edges are
// twisted against each other, a spurious twist-bend softening of O(Δθ²). With it the
// discrete Greenhill twist did not scale as 1/GJ (0.520 instead of 0.5 at n = 20 when GJ
// doubles); with per-edge curvatures it does (tests/rod_test.cc).
//
// Derivatives. With the frame variation of rod_frames.h, every director moves as
//   dm1 = -(m1·dt) t + dφ m2,  dm2 = -(m2·dt) t - dφ m1,  dφ = dθ + (Â/|e|)·de,
// and the reference twist as
//   dm = κb·de0 / (2|e0|) + κb·de1 / (2|e1|) - (Â0/|e0|)·de0 + (Â1/|e1|)·de1:
// the first two terms are [DER §6 / DVT (7)] (the holonomy of transport across the
// vertex), the Â terms the holonomy of the time-parallel reference frames themselves.
// The Hessian differentiates these once more (rod_energy.cc has the derivation).
#pragma once

#include <Eigen/Core>

#include "models/rod_frames.h"

namespace snapthread::rod {

using Vec8 = Eigen::Matrix<double, 8, 1>;
using Mat8 = Eigen::Matrix<double, 8, 8>;

// The lagged data of one edge: its unit tangent and reference director at the last
// accepted state (a ⊥ t).
struct FrameSource {
  V3 t = V3::UnitX();
  V3 a = V3::UnitY();
};

// Reference director a(t) = P_{t_s}^{t} a_s and b = t × a of an edge with unit tangent t.
inline void ReferenceFrame(const FrameSource& s, const V3& t, V3* a, V3* b) {
  *a = Transport(s.t, t, s.a);
  *b = t.cross(*a);
}

// The reference twist m at the vertex between edges e0, e1, continued from `near`.
double ReferenceTwist(const V3& e0, const V3& e1, const FrameSource& s0, const FrameSource& s1,
                      double near);

struct VertexStiffness {
  double c1 = 0.0;   // B1 / ℓ̄
  double c2 = 0.0;   // B2 / ℓ̄
  double ct = 0.0;   // GJ / ℓ̄
  double kappa1_bar = 0.0;  // natural material curvatures (dimensionless, integrated)
  double kappa2_bar = 0.0;
};

// What the two vertices of an edge share (computed once per edge and evaluation): the
// edge vector e, |e|, the unit tangent t, the reference director a = P_{t_s}^{t} a_s,
// the material directors m1, m2 at angle θ, the twist rate α = Â/|e| of the reference
// frame (the dφ of rod_energy.h's header is dθ + α·de) and, for Hessians only, its
// Jacobian ∂α/∂e = (dÂ/dt)(I - t tᵀ)/|e|² - Â tᵀ/|e|² (rod_frames.h).
struct EdgeFrame {
  V3 e, t, a, m1, m2, alpha;
  double l = 0.0;
  double theta = 0.0;
  M3 dalpha;  // set only when asked for (want_h)
};
void ComputeEdgeFrame(const V3& e, double theta, const FrameSource& s, bool want_h, EdgeFrame* f);

// Returns the vertex energy of the edges f0 = (e0, θ0), f1 = (e1, θ1); g (8) and h (8x8,
// symmetric: the lower triangle is computed and mirrored) may be null. h needs both
// frames computed with want_h. The energy does not depend on whether g and h are asked
// for (the same operations, the same bits). reference_twist (may be null): m, the value
// ReferenceTwist() gives for these edges.
double VertexEnergy(const EdgeFrame& f0, const EdgeFrame& f1, double twist_near,
                    const VertexStiffness& k, Vec8* g, Mat8* h, double* reference_twist = nullptr);

// The same from the edges themselves (both frames computed here).
double VertexEnergy(const V3& e0, const V3& e1, double theta0, double theta1,
                    const FrameSource& s0, const FrameSource& s1, double twist_near,
                    const VertexStiffness& k, Vec8* g, Mat8* h);

}  // namespace snapthread::rod
