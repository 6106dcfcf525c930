#include "snapthread/linear_solver.h"

#include "banded_ldlt.h"
#include "cholmod_ldlt.h"
#include "dense_ldlt.h"

namespace snapthread {

const char* ToString(LinearSolverStatus s) {
  switch (s) {
    case LinearSolverStatus::kSuccess: return "success";
    case LinearSolverStatus::kNumericalIssue: return "numerical issue";
    case LinearSolverStatus::kInvalidInput: return "invalid input";
  }
  return "unknown";
}

std::vector<std::string> LinearSolverNames() { return {"auto", "cholmod", "dense", "banded"}; }

// "auto" (placeholder rule until the bench numbers are in).
std::unique_ptr<SymmetricLinearSolver> MakeLinearSolver(std::string_view name, int n,
                                                        int bandwidth, std::string* error) {
  if (name == "auto") {
    if (n <= 30) return std::make_unique<DenseLdlt>();
    if (bandwidth >= 0 && bandwidth <= 16) return std::make_unique<BandedLdlt>();
    return std::make_unique<CholmodLdlt>();
  }
  if (name == "cholmod") return std::make_unique<CholmodLdlt>();
  if (name == "dense") return std::make_unique<DenseLdlt>();
  if (name == "banded") return std::make_unique<BandedLdlt>();
  if (error != nullptr) {
    *error = "unknown linear solver \"" + std::string(name) + "\" (expected one of:";
    for (const std::string& known : LinearSolverNames()) *error += " " + known;
    *error += ")";
  }
  return nullptr;
}

}  // namespace snapthread
