#include "solvers/summary.h"

#include <cstdio>

namespace snapthread {

const char* ToString(Termination t) {
  switch (t) {
    case Termination::kConverged: return "converged";
    case Termination::kBudgetSpent: return "budget-spent";
    case Termination::kLinearSolverFailed: return "linear-solver-failed";
    case Termination::kNonFinite: return "non-finite";
    case Termination::kInvalidInput: return "invalid-input";
  }
  return "unknown";
}

const char* ToString(EquilibriumStatus s) {
  switch (s) {
    case EquilibriumStatus::kRegular: return "regular";
    case EquilibriumStatus::kNearFold: return "near-fold";
    case EquilibriumStatus::kSnapped: return "snapped";
  }
  return "unknown";
}

bool SolverSummary::IsSolutionUsable() const {
  return termination == Termination::kConverged || termination == Termination::kBudgetSpent;
}

std::string SolverSummary::BriefReport() const {
  char buf[256];
  std::snprintf(buf, sizeof(buf),
                "%s (%s): %d iterations, |E_x| = %.3e, lambda_min = %.3e, %d negative pivots%s, %.1f us",
                ToString(termination), ToString(status), iterations, residual, lambda_min,
                negative_pivots, snapped ? ", snapped" : "", solve_us);
  std::string r = buf;
  if (!message.empty()) r += " — " + message;
  return r;
}

bool NearFold(double lambda_min, int negative_pivots, double lambda_ref, double degeneracy_ratio) {
  const double ref = lambda_ref > 0.0 ? lambda_ref : lambda_min;
  return negative_pivots != 0 || !(lambda_min > degeneracy_ratio * ref);
}

EquilibriumStatus DecideStatus(const SolverSummary& s, double degeneracy_ratio, bool left_branch) {
  if (left_branch) return EquilibriumStatus::kSnapped;
  return NearFold(s.lambda_min, s.negative_pivots, s.lambda_ref, degeneracy_ratio)
             ? EquilibriumStatus::kNearFold
             : EquilibriumStatus::kRegular;
}

}  // namespace snapthread
