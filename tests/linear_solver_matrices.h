// Test matrices for the LDL^T back-end tests (linear_solver_test.cc,
// make_linear_solver_test.cc): band patterns, random SPD / indefinite matrices, the
// path Laplacian. Header-only, for the one test binary.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "linalg/linear_solver.h"

namespace snapthread::test_matrices {

// ---------------------------------------------------------------------------------
// Matrices.

// Sparse matrix with the full band |i - j| <= b as its pattern (zeros stored too, so
// the pattern depends only on n and b), values from `dense`.
inline SparseMatrix BandToSparse(const Mat& dense, int b) {
  const int n = static_cast<int>(dense.rows());
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < n; ++j) {
    for (int i = std::max(0, j - b); i <= std::min(n - 1, j + b); ++i) {
      t.emplace_back(i, j, dense(i, j));
    }
  }
  SparseMatrix a(n, n);
  a.setFromTriplets(t.begin(), t.end());
  a.makeCompressed();
  return a;
}

// Random symmetric band matrix, entries uniform in [-1, 1].
inline Mat RandomSymmetricBand(int n, int b, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mat m = Mat::Zero(n, n);
  for (int j = 0; j < n; ++j) {
    for (int i = j; i <= std::min(n - 1, j + b); ++i) m(i, j) = m(j, i) = u(*rng);
  }
  return m;
}

// SPD by strict diagonal dominance: a_ii = 1 + sum_j |a_ij| (+ a random scale).
inline Mat RandomSpdBand(int n, int b, std::mt19937* rng) {
  Mat m = RandomSymmetricBand(n, b, rng);
  for (int i = 0; i < n; ++i) m(i, i) = 1.0 + m.row(i).cwiseAbs().sum() - std::abs(m(i, i));
  return m;
}

// Q diag(lambda) Q^T with `negative` eigenvalues in [-3, -0.5], the rest in [0.5, 3].
inline Mat RandomWithInertia(int n, int negative, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), mag(0.5, 3.0);
  Mat g(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) g(i, j) = u(*rng);
  }
  const Mat q = Eigen::HouseholderQR<Mat>(g).householderQ();
  Vec lambda(n);
  for (int i = 0; i < n; ++i) lambda[i] = (i < negative ? -1.0 : 1.0) * mag(*rng);
  Mat a = q * lambda.asDiagonal() * q.transpose();
  return 0.5 * (a + a.transpose());
}

inline Vec RandomVector(int n, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vec v(n);
  for (int i = 0; i < n; ++i) v[i] = u(*rng);
  return v;
}

inline double RelativeError(const Vec& x, const Vec& reference) {
  return (x - reference).norm() / reference.norm();
}

// Path-graph Laplacian (free ends): symmetric, PSD, exactly singular (constant null
// vector).
inline Mat PathLaplacian(int n) {
  Mat m = Mat::Zero(n, n);
  for (int i = 0; i + 1 < n; ++i) {
    m(i, i) += 1.0;
    m(i + 1, i + 1) += 1.0;
    m(i, i + 1) = m(i + 1, i) = -1.0;
  }
  return m;
}

}  // namespace snapthread::test_matrices
