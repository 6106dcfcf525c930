#include "linalg/linear_solver.h"

#include "linalg/banded_ldlt.h"
#include "linalg/cholmod_ldlt.h"
#include "linalg/dense_ldlt.h"

namespace snapthread {

const char* ToString(LinearSolverStatus s) {
  switch (s) {
    case LinearSolverStatus::kSuccess: return "success";
    case LinearSolverStatus::kNumericalIssue: return "numerical issue";
    case LinearSolverStatus::kInvalidInput: return "invalid input";
  }
  return "unknown";
}

LinearSolverStatus SymmetricLinearSolver::SolveMany(const Mat& b, Mat* x) const {
  if (x == nullptr || x == &b) return LinearSolverStatus::kInvalidInput;
  if (x->rows() != b.rows() || x->cols() != b.cols()) x->resize(b.rows(), b.cols());
  for (int j = 0; j < b.cols(); ++j) {
    many_rhs_ = b.col(j);
    const LinearSolverStatus st = Solve(many_rhs_, &many_x_);
    if (st != LinearSolverStatus::kSuccess) return st;
    x->col(j) = many_x_;
  }
  return LinearSolverStatus::kSuccess;
}

LinearSolverStatus SymmetricLinearSolver::InverseQuadraticForm(const Mat& b, Mat* out) const {
  if (out == nullptr || out == &b) return LinearSolverStatus::kInvalidInput;
  const LinearSolverStatus st = SolveMany(b, &quad_x_);
  if (st != LinearSolverStatus::kSuccess) return st;
  const int m = static_cast<int>(b.cols());
  if (out->rows() != m || out->cols() != m) out->resize(m, m);
  // Column dots (no temporaries); the upper triangle mirrored, so exactly symmetric.
  for (int j = 0; j < m; ++j) {
    for (int i = 0; i <= j; ++i) (*out)(i, j) = (*out)(j, i) = b.col(i).dot(quad_x_.col(j));
  }
  return LinearSolverStatus::kSuccess;
}

std::vector<std::string> LinearSolverNames() { return {"auto", "cholmod", "dense", "banded"}; }

// "auto", measured with snapthread-linear-bench (Release, 2 cores shared with other
// builds, load ~7, so single runs vary by up to ~30%; median us of Factorize+Solve on
// random SPD full-band matrices, columns cholmod / dense / banded):
//
//   half-bandwidth b = 8 (thread3d: 3 coordinates per node, nodes coupled 2 apart)
//        n    cholmod    dense   banded
//       10       1.3      0.7      0.7
//       30       3.8      4.5      2.6
//      100      14.5     51       9.4
//      300      35      772      25
//     1000     117    69800      84
//     3000     359        -     295
//   b = 30:  n = 60: 35 / 20 / 18;  n = 300: 154 / 759 / 84;  n = 1000: 585 / 63400 / 396
//   b = 2:   n = 30: 1.1 / 3.0 / 1.1;  n = 300: 11 / 971 / 11
//   dense pattern (b = n - 1): n = 30: 6.8 / 3.4 / 4.1;  n = 100: 143 / 50 / 79
//   chain closed into a ring (b = 8 plus the corner (0, n-1): sparse, bandwidth n - 1):
//        n = 30: 3.3 / 3.0 / 3.6;  n = 100: 12 / 37 / 53;  n = 1000: 119 / 28200 / 86900
//   real thread3d Hessians (snapthread-linear-bench --thread3d; 80% compressed, so
//   indefinite; the model reports b = 8):
//        n = 25: 2.1 / 2.3 / 1.7;  n = 295: 25 / 728 / 24;  n = 2995: 263 / - / 247
//
// So: a band with 2b <= n is fastest in "banded" at every size (CHOLMOD finds the same
// fill with AMD but pays for its bookkeeping, 1.05-2x); a small matrix that is not
// banded is fastest dense (n <= 30, where it also pivots); anything else, or a pattern
// whose bandwidth is unknown (bandwidth < 0) or not known to be small, goes to CHOLMOD,
// whose cost follows the fill, not the bandwidth (the ring above).
constexpr int kAutoDenseMaxN = 30;

std::unique_ptr<SymmetricLinearSolver> MakeLinearSolver(std::string_view name, int n,
                                                        int bandwidth, std::string* error) {
  if (name == "auto") {
    if (n > 0 && bandwidth >= 0 && 2 * bandwidth <= n) return std::make_unique<BandedLdlt>();
    if (n > 0 && n <= kAutoDenseMaxN) return std::make_unique<DenseLdlt>();
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
