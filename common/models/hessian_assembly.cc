#include "models/hessian_assembly.h"

#include <algorithm>
#include <cassert>
#include <cstdlib>

#include <Eigen/SparseCore>

namespace snapthread::internal {

HessianAssembly::HessianAssembly(int num_states, int num_controls)
    : num_states_(num_states), num_controls_(num_controls) {}

int HessianAssembly::AddTerm(const int* vars, int count) {
  assert(count <= kMaxPairTermVars);
  for (int i = 0; i < count; ++i) {
    assert(vars[i] >= -1 && vars[i] < num_states_ + num_controls_);
    vars_.push_back(vars[i]);
  }
  term_begin_.push_back(static_cast<int>(vars_.size()));
  return NumTerms() - 1;
}

void HessianAssembly::Finalize() {
  assert(!dynamic_ || fixed_terms_ == 0);
  FinalizePattern();
  FinalizeRuns();
  FinalizeStoreRuns();
  FinalizeBand();
  fixed_terms_ = NumTerms();
  if (dynamic_) {
    base_pattern_ = pattern_;
    base_runs_ = runs_;
    base_store_runs_ = store_runs_;
  }
}

void HessianAssembly::FinalizePattern() {
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
}

void HessianAssembly::FinalizeRuns() {
  const int n = num_states_;
  const int terms = NumTerms();
  // For each (local i, local j) of each term: the position in valuePtr(), found once by
  // a binary search in column v[j]'s sorted row indices, then merged into runs.
  run_begin_.assign(terms + 1, 0);
  runs_.clear();
  const int* outer = pattern_.outerIndexPtr();
  const int* inner = pattern_.innerIndexPtr();
  std::vector<char> reached(pattern_.nonZeros(), 0);
  for (int t = 0; t < terms; ++t) {
    run_begin_[t] = static_cast<int>(runs_.size());
    const int* v = TermVars(t);
    const int k = TermSize(t);
    for (int j = 0; j < k; ++j) {
      if (v[j] < 0 || v[j] >= n) continue;
      for (int i = 0; i < k; ++i) {
        if (v[i] < 0 || v[i] >= n) continue;
        const int* first = inner + outer[v[j]];
        const int* last = inner + outer[v[j] + 1];
        const int* it = std::lower_bound(first, last, v[i]);
        assert(it != last && *it == v[i]);
        const int index = static_cast<int>(it - inner);
        const bool is_first = reached[index] == 0;
        reached[index] = 1;
        if (!runs_.empty() && static_cast<int>(runs_.size()) > run_begin_[t]) {
          Run& run = runs_.back();
          if (run.local_col == j && run.local_row + run.len == i && run.value + run.len == index &&
              run.first == is_first) {
            ++run.len;
            continue;
          }
        }
        runs_.push_back({i, j, 1, index, is_first});
      }
    }
  }
  run_begin_[terms] = static_cast<int>(runs_.size());
}

void HessianAssembly::FinalizeStoreRuns() {
  const int terms = NumTerms();
  store_begin_.assign(4 * terms + 1, 0);
  store_runs_.clear();
  for (int t = 0; t < terms; ++t) {
    for (int k = 0; k < 4; ++k) {
      store_begin_[4 * t + k] = static_cast<int>(store_runs_.size());
      for (int r = run_begin_[t]; r < run_begin_[t + 1]; ++r) {
        const Run& run = runs_[r];
        const int kind = (run.len == 3 ? 0 : 2) + (run.first ? 0 : 1);
        if (kind == k) store_runs_.push_back(run);
      }
    }
  }
  store_begin_[4 * terms] = static_cast<int>(store_runs_.size());
}

bool HessianAssembly::SameStructure(const SparseMatrix& h) const {
  const Eigen::Index n = pattern_.cols();
  return std::equal(h.outerIndexPtr(), h.outerIndexPtr() + n + 1, pattern_.outerIndexPtr()) &&
         std::equal(h.innerIndexPtr(), h.innerIndexPtr() + pattern_.nonZeros(), pattern_.innerIndexPtr());
}

void HessianAssembly::FinalizeBand() {
  // The lower band's slots, A(i, j) with i >= j at i (b + 1) + j - i + b: along a local
  // row, consecutive variables are consecutive slots. A term whose variables are
  // consecutive states v0, v0 + 1, ... (every chain term away from the clamp and the
  // grasp) needs no table: local row i is one run of i + 1 slots (contiguous_).
  const int n = num_states_;
  const int terms = NumTerms();
  const int ld = bandwidth_ + 1;
  contiguous_.assign(terms, -1);
  band_begin_.assign(terms + 1, 0);
  band_runs_.clear();
  for (int t = 0; t < terms; ++t) {
    band_begin_[t] = static_cast<int>(band_runs_.size());
    const int* v = TermVars(t);
    const int k = TermSize(t);
    bool consecutive = v[0] >= 0 && v[k - 1] < n;
    for (int i = 1; i < k && consecutive; ++i) consecutive = v[i] == v[0] + i;
    if (consecutive && (k == 6 || k == 9 || k == 4)) {
      contiguous_[t] = v[0];
      continue;
    }
    for (int i = 0; i < k; ++i) {
      if (v[i] < 0 || v[i] >= n) continue;
      for (int j = 0; j < k; ++j) {
        if (v[j] < 0 || v[j] >= n || v[j] > v[i]) continue;
        const int slot = v[i] * ld + v[j] - v[i] + bandwidth_;
        if (static_cast<int>(band_runs_.size()) > band_begin_[t]) {
          Run& run = band_runs_.back();
          if (run.local_row == i && run.local_col + run.len == j && run.value + run.len == slot) {
            ++run.len;
            continue;
          }
        }
        band_runs_.push_back({i, j, 1, slot, false});
      }
    }
  }
  band_begin_[terms] = static_cast<int>(band_runs_.size());
}

namespace {

// The lower triangle of a K x K local Hessian (column-major, leading dimension ld) added
// to the band rows v0 .. v0 + K - 1: row i's entries (i, 0 .. i) are band slots
// (v0 + i) (b + 1) + b - i .. (v0 + i) (b + 1) + b, contiguous.
template <int K>
inline void AddContiguousBlock(const double* local_h, int ld, double* band, int band_ld, int v0) {
  double* row = band + static_cast<std::ptrdiff_t>(v0) * band_ld + (band_ld - 1);
#pragma GCC unroll 16
  for (int i = 0; i < K; ++i, row += band_ld) {
#pragma GCC unroll 16
    for (int j = 0; j <= i; ++j) row[j - i] += local_h[i + j * ld];
  }
}

}  // namespace

void HessianAssembly::AddBandHessian(int term, const double* local_h, int ld, double* band) const {
  const int band_ld = bandwidth_ + 1;
  const int v0 = contiguous_[term];
  if (v0 >= 0) {
    switch (TermSize(term)) {
      case 4: AddContiguousBlock<4>(local_h, ld, band, band_ld, v0); return;
      case 6: AddContiguousBlock<6>(local_h, ld, band, band_ld, v0); return;
      case 9: AddContiguousBlock<9>(local_h, ld, band, band_ld, v0); return;
      default: break;
    }
  }
  // Entry (i, j) of the local Hessian is local_h[i + j ld]: a run along a row has stride ld.
  for (const Run* run = band_runs_.data() + band_begin_[term]; run != band_runs_.data() + band_begin_[term + 1];
       ++run) {
    const double* src = local_h + run->local_row + run->local_col * ld;
    double* dst = band + run->value;
    for (int r = 0; r < run->len; ++r) dst[r] += src[r * ld];
  }
}

void HessianAssembly::AddGradient(int term, const double* local_g, double* g) const {
  const int v0 = contiguous_[term];
  if (v0 >= 0) {  // the same additions in the same order, without the index checks
    double* dst = g + v0;
    for (int i = 0, k = TermSize(term); i < k; ++i) dst[i] += local_g[i];
    return;
  }
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
  const Run* run = runs_.data() + run_begin_[term];
  const Run* end = runs_.data() + run_begin_[term + 1];
  for (; run != end; ++run) {
    const double* src = local_h + run->local_row + run->local_col * ld;
    double* dst = values + run->value;
    for (int r = 0; r < run->len; ++r) dst[r] += src[r];
  }
}

void HessianAssembly::StoreHessian(int term, const double* local_h, int ld, double* values) const {
  const Run* runs = store_runs_.data();
  const int* begin = store_begin_.data() + 4 * term;
  // A node's three coordinates make most runs 3 long: those unrolled.
  for (const Run* run = runs + begin[0]; run != runs + begin[1]; ++run) {
    const double* src = local_h + run->local_row + run->local_col * ld;
    double* dst = values + run->value;
    dst[0] = src[0], dst[1] = src[1], dst[2] = src[2];
  }
  for (const Run* run = runs + begin[1]; run != runs + begin[2]; ++run) {
    const double* src = local_h + run->local_row + run->local_col * ld;
    double* dst = values + run->value;
    dst[0] += src[0], dst[1] += src[1], dst[2] += src[2];
  }
  for (const Run* run = runs + begin[2]; run != runs + begin[3]; ++run) {
    const double* src = local_h + run->local_row + run->local_col * ld;
    double* dst = values + run->value;
    for (int r = 0; r < run->len; ++r) dst[r] = src[r];
  }
  for (const Run* run = runs + begin[3]; run != runs + begin[4]; ++run) {
    const double* src = local_h + run->local_row + run->local_col * ld;
    double* dst = values + run->value;
    for (int r = 0; r < run->len; ++r) dst[r] += src[r];
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
