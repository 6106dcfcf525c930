#include "fold_search.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>

#include "linalg/linear_solver.h"
#include "models/registry.h"
#include "solvers/eigen_tracking.h"
#include "tracking/make_tracker.h"

namespace snapthread::server {
namespace {

// Bisection steps are bounded: reach / tolerance is at most 2^40.
constexpr int kMaxBisections = 40;
constexpr int kMaxMarchSteps = 64;

}  // namespace

FoldSearch::FoldSearch(const Scene& scene) {
  Scene own = scene;
  own.solver.max_iterations = 0;  // unlimited (capped by the solver's safety net)
  own.solver.max_time_us = 0.0;
  tracker_ = MakeTracker(own);
  jump_threshold_ = 0.1 * SnapLengthScale(scene.params);
  dim_ = std::min(tracker_->model().SpatialDimension(), tracker_->model().NumControls());
}

bool FoldSearch::OnBranch(const Vec& x, const Vec& u_x, const Vec& u) {
  // Resume solves at u warm-started from x with the higher-order solver: on the branch
  // it converges next to x; past the fold its reduction finds the followed minimum gone
  // and the snap minimiser takes the state to the other branch (DESIGN.md #3-#4).
  const TrackResult& r = tracker_->Resume(x, u);
  if (!r.summary.IsSolutionUsable()) return false;
  if ((tracker_->state() - x).lpNorm<Eigen::Infinity>() <= jump_threshold_) return true;
  // A large change is not yet a snap: near the fold the branch itself moves like
  // sqrt(distance) ((2.54-2.55)), so a march step can move the state by more than the
  // threshold while it stays on the branch (that read as a fold that was not there,
  // and the search then reported none). The two branches coexist before the fold
  // (hysteresis): solved back at u_x from the new state, the same branch returns to x,
  // the other one stays away from it.
  const Vec at_u = tracker_->state();
  const TrackResult& back = tracker_->Resume(at_u, u_x);
  const bool same = back.summary.IsSolutionUsable() &&
                    (tracker_->state() - x).lpNorm<Eigen::Infinity>() <= jump_threshold_;
  tracker_->Resume(at_u, u);  // the tracker holds the state at u, as its callers expect
  return same;
}

bool FoldSearch::Bracket(const Vec& x, const Vec& u, const Vec& d, double reach, double step,
                         double tol, double* s_lo, Vec* x_lo, double* s_hi) {
  *s_lo = 0.0;
  *x_lo = x;
  double hi = -1.0;
  for (int k = 1; k <= kMaxMarchSteps; ++k) {
    const double s = std::min(reach, k * step);
    if (OnBranch(*x_lo, u + *s_lo * d, u + s * d)) {
      *s_lo = s;
      *x_lo = tracker_->state();
      if (s >= reach) return false;
    } else {
      hi = s;
      break;
    }
  }
  if (hi < 0.0) return false;
  for (int it = 0; it < kMaxBisections && hi - *s_lo > tol; ++it) {
    const double mid = 0.5 * (*s_lo + hi);
    if (OnBranch(*x_lo, u + *s_lo * d, u + mid * d)) {
      *s_lo = mid;
      *x_lo = tracker_->state();
    } else {
      hi = mid;
    }
  }
  // Leave the tracker on the other branch just past the fold (the post-snap model).
  if (OnBranch(*x_lo, u + *s_lo * d, u + hi * d)) return false;  // the fold moved under round-off
  *s_hi = hi;
  return true;
}

bool FoldSearch::FoldNormal(const Vec& x, const Vec& u, Vec* normal) {
  const Model& model = tracker_->model();
  SparseMatrix h = model.HessianPattern();
  model.Hessian(x, u, &h);
  std::string error;
  auto factor = MakeLinearSolver("auto", model.NumStates(), model.HessianBandwidth(), &error);
  if (!factor || factor->Analyze(h) != LinearSolverStatus::kSuccess ||
      factor->Factorize(h) != LinearSolverStatus::kSuccess) {
    return false;
  }
  // Next to the fold lambda_min is tiny, so inverse iteration converges at once to v.
  SmallestEigenpair eig;
  eig.Update(*factor, h, 20);
  Mat exu(model.NumStates(), model.NumControls());
  model.MixedHessian(x, u, &exu);
  // grad_u phi1 = E_ux v: the normal of the fold set (see the header), in all of the
  // controls: a fold reached by turning the grasp has its normal in the turning ones.
  const Vec n = exu.transpose() * eig.vector();
  const double norm = n.norm();
  if (!(norm > 0.0) || !n.allFinite()) return false;
  *normal = n / norm;
  return true;
}

FoldPrediction FoldSearch::Find(const Vec& x, const Vec& u, const Vec& d,
                                const FoldSearchOptions& options) {
  FoldPrediction p;
  try {
    const double step = options.reach / 16.0;
    double s_lo = 0.0, s_hi = 0.0;
    Vec x_lo;
    if (!Bracket(x, u, d, options.reach, step, options.tolerance, &s_lo, &x_lo, &s_hi)) {
      p.why_not = "the branch goes on within reach";
      return p;
    }
    p.x_after = tracker_->state();
    p.u_after = u + s_hi * d;
    p.after = tracker_->last();
    p.x_before = x_lo;
    p.u_before = u + s_lo * d;
    p.u_fold = u + (0.5 * (s_lo + s_hi)) * d;
    if (!FoldNormal(p.x_before, p.u_before, &p.normal)) {
      p.why_not = "no normal";
      return p;
    }
    // The hand crosses along +normal: it moves along d towards the fold.
    if (p.normal.dot(d) < 0.0) p.normal = -p.normal;
    // A fold the hand's motion hardly reaches: the boundary is not what the hand crosses.
    if (p.normal.dot(d) < 0.1 * d.norm()) {
      p.why_not = "the motion hardly reaches it";
      return p;
    }
    // Curvature from two side searches at +-lateral along a positional tangent t (normal
    // to the normal's positional part, in the plane of d's positional part when the hand
    // moves): the boundary n.w = (kappa/2) |w_t|^2 puts the side fold points
    // kappa lateral^2 / 2 further along n. t is normal to n, so the sides start on the
    // tangent plane.
    const Vec n_pos = p.normal.head(dim_);
    const double np2 = n_pos.squaredNorm();
    Vec t = d.head(dim_);
    if (np2 > 0.0) t -= n_pos * (n_pos.dot(t) / np2);
    if (t.norm() < 1e-6 && dim_ >= 2) {
      // The hand turns in place (or moves along the normal): the positional axis least
      // along the normal.
      t = Vec::Zero(dim_);
      int axis = 0;
      for (int i = 1; i < dim_; ++i) {
        if (std::abs(n_pos[i]) < std::abs(n_pos[axis])) axis = i;
      }
      t[axis] = 1.0;
      if (np2 > 0.0) t -= n_pos * (n_pos.dot(t) / np2);
    }
    if (t.norm() > 1e-6) {
      t.normalize();
      Vec t_full = Vec::Zero(u.size());
      t_full.head(dim_) = t;
      const Vec& n_full = p.normal;
      const double lat = options.lateral;
      double offsets[2];
      int found = 0;
      for (int side = 0; side < 2; ++side) {
        const Vec start = p.u_before - lat * n_full + (side == 0 ? lat : -lat) * t_full;
        if (!OnBranch(p.x_before, p.u_before, start)) break;
        const Vec xs = tracker_->state();
        double lo = 0.0, hi = 0.0;
        Vec x_side;
        if (!Bracket(xs, start, n_full, 4.0 * lat, lat / 4.0, options.tolerance, &lo, &x_side, &hi))
          break;
        offsets[found++] = 0.5 * (lo + hi) - lat - (p.u_fold - p.u_before).dot(n_full);
      }
      if (found == 2) p.curvature = (offsets[0] + offsets[1]) / (lat * lat);
      if (!std::isfinite(p.curvature)) p.curvature = 0.0;
    }
    p.found = true;
  } catch (const std::exception&) {
    p.found = false;  // numeric trouble in the search: no prediction, never a bad one
    p.why_not = "numeric trouble";
  }
  return p;
}

}  // namespace snapthread::server
