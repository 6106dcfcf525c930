// The seed's bifurcation-aware solver (§2.3.5, §2.4, Appendix A-B), with the five
// operational choices of shared/DESIGN.md ("What a prototype of this method showed").
#pragma once

#include "solvers/newton_solver.h"

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

class HigherOrderSolver final : public SolverBase {
 public:
  HigherOrderSolver(const Model& model, const SolverOptions& options);
  SolverSummary Solve(const Vec& u, Vec* x) override;

 private:
  enum class StepResult { kAccepted, kSnap, kFailed };
  // One iteration of the one-direction reduction of §2.4.1.3 at x (H factored in
  // factor_, its lowest eigenvector in eig_).
  StepResult ReductionStep(const Vec& u, Vec* x, SolverSummary* s);
  // Factorises H_{-k,-k} (row and column k replaced by the identity) into alt_factor_.
  LinearSolverStatus FactorRestricted(int k, SolverSummary* s);
  // Finishes a snap inside this control step (DESIGN.md #4): inertia-corrected Newton
  // with Armijo backtracking until converged, past the iteration budget.
  bool FinishSnap(const Vec& u, Vec* x, SolverSummary* s);

  std::vector<int> col_k_rows_, col_k_pos_, row_k_pos_;
  Vec delta_, vt_, w_, rhs_, gp_, gm_, xs_, g_trial_;
};

}  // namespace snapthread
