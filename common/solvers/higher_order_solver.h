// The seed's bifurcation-aware solver (§2.3.5, §2.4, Appendix A-B), with the five
// operational choices of shared/DESIGN.md ("What a prototype of this method showed").
#pragma once

#include "solvers/solver_base.h"

namespace snapthread {

// Coefficients of the energy along the curved separation c(s) = x + d + s v' + s^2 w,
// phi(s) - phi(0) = phi1 s + phi2 s^2 + phi3 s^3 + phi4 s^4 (2.54-2.55).
struct ReducedQuartic {
  double phi1 = 0.0, phi2 = 0.0, phi3 = 0.0, phi4 = 0.0;
};

// The followed minimum of the reduced energy (DESIGN.md #3): the smallest root of the
// cubic truncation's derivative phi1 + 2 phi2 s + 3 phi3 s^2 in the downhill direction
// -sign(phi1), refined by Newton on the quartic's derivative, |s| <= cap. Returns
// false when there is no such root: the followed minimum has vanished (a snap).
bool FollowedMinimum(const ReducedQuartic& q, double cap, double* s);

// The same on a flat valley's quartic (E_xx positive definite, phi2 ~ 0: the cubic
// truncation may have no downhill minimum while the quartic (2.54-2.55), held by phi4 > 0,
// has one): the quartic's nearest downhill minimum, when it lies within `reach`, capped
// at `cap`. False when there is none that near: the followed minimum has gone (a snap).
bool QuarticMinimumNearby(const ReducedQuartic& q, double cap, double reach, double* s);

class HigherOrderSolver final : public SolverBase {
 public:
  HigherOrderSolver(const Model& model, const SolverOptions& options);
  SolverSummary Solve(const Vec& u, Vec* x) override;

 private:
  enum class StepResult { kAccepted, kSnap, kFailed };
  // One iteration of the one-direction reduction of §2.4.1.3 at x (H factored in
  // factor_, its lowest eigenvector in eig_).
  // In a flat valley (flat_valley: E_xx positive definite, a Newton step too long for its
  // quadratic model) the quartic's own minimum is followed too (QuarticMinimumNearby).
  StepResult ReductionStep(const Vec& u, Vec* x, bool flat_valley, SolverSummary* s);
  // Factorises H_{-k,-k} (row and column k replaced by the identity) into alt_factor_.
  LinearSolverStatus FactorRestricted(int k, SolverSummary* s);
  // Finishes a snap inside this control step (DESIGN.md #4): inertia-corrected Newton
  // with Armijo backtracking until converged, past the iteration budget.
  bool FinishSnap(const Vec& u, Vec* x, SolverSummary* s);
  // ReductionStep's parts, in order: the graph tangent v' (vt_) and the complement's
  // Newton step delta_ with the restricted factorisation; the reduced quartic (2.54-2.55)
  // from central differences of E_x along v' (and w_, (2.52)); the energy-decreasing
  // backtrack along the curve x + delta + s v' + s^2 w from energy e0.
  bool ReductionDirections(int k);
  bool ReducedQuarticAt(const Vec& u, const Vec& x, int k, SolverSummary* s, ReducedQuartic* q);
  StepResult BacktrackAlongCurve(const Vec& u, Vec* x, double s_star, double e0);

  // Solve's steps. SnapAndStop finishes a snap inside this update (DESIGN.md #4) and
  // leaves |E_x| in *r. CheckNewtonStep computes the Newton step at x and judges it: a
  // factorisation failure, too long (a snap), refused (it raises E near a fold), or taken
  // (*trial_gradient: g_trial_ holds E_x at the trial state xs_).
  enum class NewtonCheck { kTake, kRefused, kSnap, kFailed };
  void SnapAndStop(const Vec& u, Vec* x, SolverSummary* s, double* r);
  // A budget spent in a flat valley: minimise on past the budget (no snap: the state is
  // still on its branch), converged on the same stopping rule; |E_x| in *r.
  void FinishFlatValley(const Vec& u, Vec* x, SolverSummary* s, double* r);
  // After a Newton step longer than the reduction's cap (E_xx positive definite): true
  // when x is in a flat valley (the iteration follows it with the reduction); false when
  // the solve has ended here (converged at round-off, or a stiff E_xx: a snap, finished).
  bool EnterFlatValley(const Vec& u, Vec* x, double lambda0, SolverSummary* s, double* r);
  // The largest |diagonal entry| of E_xx at the factorised state (the flatness scale).
  double MaxHessianDiagonal();
  NewtonCheck CheckNewtonStep(const Vec& u, const Vec& x, double lambda0, SolverSummary* s, bool* trial_gradient);
  // Takes the Newton step and updates |E_x| in *r; true when it did not halve |E_x|.
  bool NewtonIteration(const Vec& u, Vec* x, bool trial_gradient, double* r, SolverSummary* s);
  // A reduction step (or a globalised one where it fails) from x; false when the
  // iteration loop ends (a snap finished, or no descent step).
  // In a flat valley (see ReductionStep) a step that does not halve |E_x| is no snap:
  // the valley is followed on (the next iteration judges the Newton step again).
  bool ReductionIteration(const Vec& u, Vec* x, LinearSolverStatus st, bool flat_valley, int* reduction_stalls,
                          double* r, SolverSummary* s);

  // kFlatValleyRatio times E_xx's largest diagonal entry where a long Newton step was
  // last judged (0: never): lambda_min below it is a flat valley.
  double flat_lambda_ = 0.0;
  std::vector<int> col_k_rows_, col_k_pos_, row_k_pos_;
  Vec delta_, vt_, w_, rhs_, gp_, gm_, xs_, g_trial_;
};

}  // namespace snapthread
