// The rod's material frame and twist on the drawn tube: the message's
// per-edge director d1 and twist density (thread_shape_t.frames) carried onto the rings
// of the spline-smoothed tube, and the twist colour map. No OpenGL here (testable).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "mesh_builder.h"

namespace snapthread::viewer {

// The stripe along d1: a dark band of ±kStripeHalfColumns faces (columns) of the tube's
// kStripedTubeSides, i.e. ±22.5°, centred on d1.
inline constexpr int kStripedTubeSides = 16;
inline constexpr int kStripeHalfColumns = 1;
inline const Rgb kStripeColor(0.06f, 0.06f, 0.06f);
// Twist colour map (diverging): 0 is the tube's own (state) colour; right-handed twist
// (d1 turning counter-clockwise about the tangent, positive density) blends towards green,
// left-handed towards violet, reaching kTwistBlendMax of the hue at |twist| >= one turn
// per drawn length (2π / L).
inline const Rgb kTwistPositiveColor(0.30f, 0.85f, 0.25f);
inline const Rgb kTwistNegativeColor(0.50f, 0.30f, 1.00f);
inline constexpr float kTwistBlendMax = 0.8f;

// The colour of twist density `twist` (rad per model length) on a tube of colour `base`,
// full scale at `full_scale` (rad per model length, > 0).
Rgb TwistColor(const Rgb& base, double twist, double full_scale);

// One turn per length: 2π / L, L the length of the polyline through `nodes` (model units).
double TwistFullScale(const std::vector<Eigen::Vector3d>& nodes);

// Per ring of the tube along the spline through the nodes: the angle of d1 from the ring
// frame's normal towards its binormal, and the twist density.
struct MaterialRings {
  std::vector<double> angle;
  std::vector<double> twist;
};

// `frames` holds one row (d1 x, y, z, twist density; 4 entries) per edge (node j to j + 1), `path`
// is CatmullRomCurve(nodes, samples_per_segment) and `curve` its rotation-minimising
// frames. Edge j's row sits at the ring of its midpoint, j·s + s/2: there d1 is measured
// against the ring frame, angles are unwrapped edge to edge (consecutive edges turn by less
// than π), and between midpoints the angle and the twist are interpolated linearly (held
// constant beyond the end midpoints). The ring frame is d1's transport along the spline,
// so the stripe turns about the tube exactly by the interpolated material angle and never
// flips. Empty when the counts do not fit.
MaterialRings InterpolateMaterialFrames(const std::vector<std::vector<double>>& frames,
                                        int samples_per_segment,
                                        const std::vector<CurveFrame>& curve);

}  // namespace snapthread::viewer
