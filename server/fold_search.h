// Snap-ahead, the search: where along the hand's motion the followed branch
// ends in a fold, the fold boundary there (point, normal, curvature in control space)
// and the equilibrium the state snaps to past it. Runs off the solve thread on its own
// tracker (own model and solver), so the served tracker is never touched.
//
// The fold set is lambda_min(x*(u), u) = 0. In the one-variable normal form along the
// degenerate direction v (§2.4.1.3, (2.54-2.55)) the reduced energy is
//   phi(s; u) = phi1(u) s + phi2(u) s^2 + phi3 s^3 + ...,  phi1 = E_x . v, phi2 = lambda/2,
// and the followed minimum exists while phi2^2 >= 3 phi1 phi3. At the fold phi2 = 0, so
// the gradient of that discriminant in u is -12 phi3 grad_u phi1 and the fold's normal in
// u is grad_u phi1 = E_ux v (the u-derivative of the linear coefficient). Along a line,
// lambda ~ sqrt(distance) near the fold, so lambda^2 is linear in the distance: the
// estimate distance = lambda^2 / |d(lambda^2)/ds| (the normal form's square-root law),
// refined here by bisection on "the branch still exists" (the tracker did not snap).
#pragma once

#include <memory>

#include "numeric/types.h"
#include "scene/scene.h"
#include "tracking/tracker.h"

namespace snapthread::server {

struct FoldPrediction {
  bool found = false;
  Vec u_fold;           // the fold point, full controls (model units)
  Vec normal;           // unit, all controls (a grip's too); the hand crosses along +normal
  // Of the boundary n.w = (curvature / 2) |w_t|^2 (w = u - u_fold; w_t its part along
  // positional directions normal to n): > 0 bends away from the approaching hand.
  // 1 / model unit.
  double curvature = 0.0;
  Vec x_before;         // last state on the followed branch (at u_before)
  Vec u_before;
  Vec x_after;          // the equilibrium past the fold (the other branch) at u_after
  Vec u_after;
  TrackResult after;    // its force and K (model units)
  const char* why_not = "";  // found = false: why (for the log)
};

struct FoldSearchOptions {
  double reach = 1.0;        // how far along the direction to look, model units
  double tolerance = 1e-4;   // bracket width of the fold point, model units
  double lateral = 0.05;     // offset of the two side searches for the curvature
};

class FoldSearch {
 public:
  // Its own tracker from the scene (MakeTracker) with an unlimited iteration budget and
  // no time budget: accuracy, not latency, matters off the solve thread.
  explicit FoldSearch(const Scene& scene);
  // From the equilibrium x at controls u, along the unit direction d (full controls: the
  // hand's motion, turning a grip included; the models see a grip direction's
  // direction only, so a line of grip controls is the great circle it turns through).
  // found = false when the branch goes on for `reach`.
  // Never throws for numeric trouble (found = false).
  FoldPrediction Find(const Vec& x, const Vec& u, const Vec& d, const FoldSearchOptions& options);
  // Its model (for building messages once no search runs).
  const Model& model() const { return tracker_->model(); }

 private:
  // Solves at u from x, the equilibrium at u_x; true when the state stayed on x's
  // branch. The tracker then holds the state at u.
  bool OnBranch(const Vec& x, const Vec& u_x, const Vec& u);
  // March from (x, u) along d by `step` up to `reach`, then bisect to `tol`: the last
  // parameter on the branch (*s_lo, its state *x_lo) and the first past it (*s_hi; the
  // tracker then holds the snapped state). False when no fold within reach.
  bool Bracket(const Vec& x, const Vec& u, const Vec& d, double reach, double step, double tol,
               double* s_lo, Vec* x_lo, double* s_hi);
  // E_ux v at (x, u) with v the lowest eigenvector of E_xx (inverse iteration), unit,
  // all controls.
  bool FoldNormal(const Vec& x, const Vec& u, Vec* normal);

  std::unique_ptr<EquilibriumTracker> tracker_;
  double jump_threshold_ = 0.1;
  int dim_ = 0;  // positional controls
};

}  // namespace snapthread::server
