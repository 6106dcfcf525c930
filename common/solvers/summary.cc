#include "solvers/summary.h"

#include <cmath>
#include <cstdio>

namespace snapthread {

const char* ToString(Termination t) {
  switch (t) {
    case Termination::kConverged: return "converged";
    case Termination::kBudgetSpent: return "budget-spent";
    case Termination::kLinearSolverFailed: return "linear-solver-failed";
    case Termination::kNonFinite: return "non-finite";
    case Termination::kInvalidInput: return "invalid-input";
    case Termination::kSnapping: return "snapping";
    case Termination::kAccuracyLimited: return "accuracy-limited";
  }
  return "unknown";
}

const char* ToString(EquilibriumStatus s) {
  switch (s) {
    case EquilibriumStatus::kRegular: return "regular";
    case EquilibriumStatus::kNearFold: return "near-fold";
    case EquilibriumStatus::kSnapped: return "snapped";
    case EquilibriumStatus::kSnapping: return "snapping";
    case EquilibriumStatus::kFailed: return "failed";
  }
  return "unknown";
}

bool SolverSummary::IsSolutionUsable() const {
  const bool usable_end = IsConverged() || termination == Termination::kBudgetSpent ||
                          termination == Termination::kSnapping;
  return usable_end && std::isfinite(residual) && std::isfinite(energy);
}

std::string SolverSummary::BriefReport() const {
  char buf[256];
  std::snprintf(buf, sizeof(buf),
                "%s (%s): %d iterations, |E_x| = %.3e%s, force error %.3e, lambda_min = %.3e, %d negative pivots%s, "
                "%.1f us",
                ToString(termination), ToString(status), iterations, residual, at_round_off ? " (round-off)" : "",
                force_error, lambda_min, negative_pivots, snapped ? ", snapped" : "", solve_us);
  std::string r = buf;
  if (!message.empty()) r += " — " + message;
  return r;
}

bool NearFold(double lambda_min, int negative_pivots, double lambda_ref, double degeneracy_ratio) {
  const double ref = lambda_ref > 0.0 ? lambda_ref : lambda_min;
  return negative_pivots != 0 || !(lambda_min > degeneracy_ratio * ref);
}

EquilibriumStatus DecideStatus(const SolverSummary& s, double degeneracy_ratio, bool left_branch) {
  if (!s.IsSolutionUsable()) return EquilibriumStatus::kFailed;
  if (s.termination == Termination::kSnapping) return EquilibriumStatus::kSnapping;
  if (left_branch) return EquilibriumStatus::kSnapped;
  return NearFold(s.lambda_min, s.negative_pivots, s.lambda_ref, degeneracy_ratio)
             ? EquilibriumStatus::kNearFold
             : EquilibriumStatus::kRegular;
}

}  // namespace snapthread
