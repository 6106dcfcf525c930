#include "hessian_assembly.h"

#include <algorithm>
#include <cassert>
#include <cstdlib>

#include <Eigen/SparseCore>

namespace snapthread::internal {

HessianAssembly::HessianAssembly(int num_states, int num_controls)
    : num_states_(num_states), num_controls_(num_controls) {}

int HessianAssembly::AddTerm(const int* vars, int count) {
  assert(count <= kMaxTermVars);
  for (int i = 0; i < count; ++i) {
    assert(vars[i] >= -1 && vars[i] < num_states_ + num_controls_);
    vars_.push_back(vars[i]);
  }
  term_begin_.push_back(static_cast<int>(vars_.size()));
  return NumTerms() - 1;
}

void HessianAssembly::Finalize() {
  const int n = num_states_;
  const int terms = NumTerms();
  std::vector<Eigen::Triplet<double, int>> triplets;
  touches_controls_.assign(terms, 0);
  for (int t = 0; t < terms; ++t) {
    const int* v = TermVars(t);
    const int k = TermSize(t);
    for (int i = 0; i < k; ++i) {
      if (v[i] >= n) touches_controls_[t] = 1;
      for (int j = 0; j < k; ++j) {
        if (v[i] >= 0 && v[i] < n && v[j] >= 0 && v[j] < n) triplets.emplace_back(v[i], v[j], 0.0);
      }
    }
  }
  pattern_.resize(n, n);
  // Duplicates are summed: values stay 0, only the structure matters here.
  pattern_.setFromTriplets(triplets.begin(), triplets.end());
  pattern_.makeCompressed();

  bandwidth_ = 0;
  for (int col = 0; col < n; ++col) {
    for (SparseMatrix::InnerIterator it(pattern_, col); it; ++it) {
      bandwidth_ = std::max(bandwidth_, std::abs(static_cast<int>(it.row()) - col));
    }
  }

  // For each (local i, local j) of each term: the position in valuePtr(), found once by
  // a binary search in column v[j]'s sorted row indices.
  value_begin_.assign(terms, 0);
  value_index_.clear();
  const int* outer = pattern_.outerIndexPtr();
  const int* inner = pattern_.innerIndexPtr();
  for (int t = 0; t < terms; ++t) {
    value_begin_[t] = static_cast<int>(value_index_.size());
    const int* v = TermVars(t);
    const int k = TermSize(t);
    for (int j = 0; j < k; ++j) {
      for (int i = 0; i < k; ++i) {
        int index = -1;
        if (v[i] >= 0 && v[i] < n && v[j] >= 0 && v[j] < n) {
          const int* first = inner + outer[v[j]];
          const int* last = inner + outer[v[j] + 1];
          const int* it = std::lower_bound(first, last, v[i]);
          assert(it != last && *it == v[i]);
          index = static_cast<int>(it - inner);
        }
        value_index_.push_back(index);  // column-major: i + j * k
      }
    }
  }
}

void HessianAssembly::AddGradient(int term, const double* local_g, double* g) const {
  const int* v = TermVars(term);
  const int k = TermSize(term);
  for (int i = 0; i < k; ++i) {
    if (v[i] >= 0 && v[i] < num_states_) g[v[i]] += local_g[i];
  }
}

void HessianAssembly::AddControlGradient(int term, const double* local_g, double* eu) const {
  const int* v = TermVars(term);
  const int k = TermSize(term);
  for (int i = 0; i < k; ++i) {
    if (v[i] >= num_states_) eu[v[i] - num_states_] += local_g[i];
  }
}

void HessianAssembly::AddHessian(int term, const double* local_h, int ld, double* values) const {
  const int k = TermSize(term);
  const int* index = value_index_.data() + value_begin_[term];
  for (int j = 0; j < k; ++j) {
    for (int i = 0; i < k; ++i) {
      const int m = index[i + j * k];
      if (m >= 0) values[m] += local_h[i + j * ld];
    }
  }
}

void HessianAssembly::AddMixedHessian(int term, const double* local_h, int ld, Mat* exu) const {
  const int* v = TermVars(term);
  const int k = TermSize(term);
  for (int j = 0; j < k; ++j) {
    if (v[j] < num_states_) continue;
    for (int i = 0; i < k; ++i) {
      if (v[i] >= 0 && v[i] < num_states_) (*exu)(v[i], v[j] - num_states_) += local_h[i + j * ld];
    }
  }
}

void HessianAssembly::AddControlHessian(int term, const double* local_h, int ld, Mat* euu) const {
  const int* v = TermVars(term);
  const int k = TermSize(term);
  for (int j = 0; j < k; ++j) {
    if (v[j] < num_states_) continue;
    for (int i = 0; i < k; ++i) {
      if (v[i] >= num_states_) (*euu)(v[i] - num_states_, v[j] - num_states_) += local_h[i + j * ld];
    }
  }
}

}  // namespace snapthread::internal
