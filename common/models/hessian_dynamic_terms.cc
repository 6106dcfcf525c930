// HessianAssembly's dynamic terms (self-contact): SetDynamicTerms replaces the pair terms
// and re-indexes the pattern and the fixed terms' scatter runs into it.
#include "models/hessian_assembly.h"

#include <algorithm>
#include <cassert>
#include <utility>
#include <vector>

namespace snapthread::internal {

void HessianAssembly::SetDynamicTerms(const std::vector<int>& vars, const std::vector<int>& begin) {
  assert(dynamic_);
  const std::vector<std::pair<int, int>> extra = ReplaceDynamicVars(vars, begin);
  std::vector<int> outer, inner, moved;
  MergeDynamicPattern(extra, &outer, &inner, &moved);
  IndexDynamicRuns(outer, inner, moved);
  ++version_;
}

std::vector<std::pair<int, int>> HessianAssembly::ReplaceDynamicVars(const std::vector<int>& vars,
                                                                    const std::vector<int>& begin) {
  const int n = num_states_;
  const int count = static_cast<int>(begin.size()) - 1;
  vars_.resize(term_begin_[fixed_terms_]);
  term_begin_.resize(fixed_terms_ + 1);
  std::vector<std::pair<int, int>> extra;  // (column, row) of the dynamic terms' entries
  for (int k = 0; k < count; ++k) {
    for (int p = begin[k]; p < begin[k + 1]; ++p) vars_.push_back(vars[p]);
    term_begin_.push_back(static_cast<int>(vars_.size()));
    for (int a = begin[k]; a < begin[k + 1]; ++a) {
      if (vars[a] < 0 || vars[a] >= n) continue;
      for (int b = begin[k]; b < begin[k + 1]; ++b) {
        if (vars[b] >= 0 && vars[b] < n) extra.emplace_back(vars[a], vars[b]);
      }
    }
  }
  std::sort(extra.begin(), extra.end());
  extra.erase(std::unique(extra.begin(), extra.end()), extra.end());
  return extra;
}

void HessianAssembly::MergeDynamicPattern(const std::vector<std::pair<int, int>>& extra, std::vector<int>* outer_out,
                                          std::vector<int>* inner_out, std::vector<int>* moved_out) {
  const int n = num_states_;
  // pattern_ = base ∪ extra, column by column (both sorted), and where each base entry
  // went (a run's rows are consecutive integers, so nothing lands inside one: the fixed
  // terms' runs stay runs, shifted).
  const int* bo = base_pattern_.outerIndexPtr();
  const int* bi = base_pattern_.innerIndexPtr();
  std::vector<int>& outer = *outer_out;
  std::vector<int>& inner = *inner_out;
  std::vector<int>& moved = *moved_out;
  outer.assign(n + 1, 0);
  inner.clear();
  moved.resize(base_pattern_.nonZeros());
  inner.reserve(base_pattern_.nonZeros() + extra.size());
  size_t e = 0;
  for (int j = 0; j < n; ++j) {
    int q = bo[j];
    while (q < bo[j + 1] || (e < extra.size() && extra[e].first == j)) {
      const bool take_base = q < bo[j + 1] && (e >= extra.size() || extra[e].first != j || bi[q] <= extra[e].second);
      if (take_base) {
        if (e < extra.size() && extra[e].first == j && extra[e].second == bi[q]) ++e;
        moved[q] = static_cast<int>(inner.size());
        inner.push_back(bi[q++]);
      } else {
        inner.push_back(extra[e++].second);
      }
    }
    outer[j + 1] = static_cast<int>(inner.size());
  }
  pattern_.resize(n, n);
  pattern_.resizeNonZeros(static_cast<Eigen::Index>(inner.size()));
  std::copy(outer.begin(), outer.end(), pattern_.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), pattern_.innerIndexPtr());
  std::fill(pattern_.valuePtr(), pattern_.valuePtr() + inner.size(), 0.0);
}

void HessianAssembly::IndexDynamicRuns(const std::vector<int>& outer, const std::vector<int>& inner,
                                       const std::vector<int>& moved) {
  const int n = num_states_;
  runs_ = base_runs_;
  for (Run& r : runs_) r.value = moved[r.value];
  store_runs_ = base_store_runs_;
  for (Run& r : store_runs_) r.value = moved[r.value];
  run_begin_.resize(fixed_terms_ + 1);
  touches_controls_.resize(fixed_terms_);
  contiguous_.resize(fixed_terms_);
  const int terms = NumTerms();
  for (int t = fixed_terms_; t < terms; ++t) {
    const int* v = TermVars(t);
    const int k = TermSize(t);
    bool controls = false;
    for (int j = 0; j < k; ++j) {
      if (v[j] >= n) controls = true;
      if (v[j] < 0 || v[j] >= n) continue;
      for (int i = 0; i < k; ++i) {
        if (v[i] < 0 || v[i] >= n) continue;
        const int* first = inner.data() + outer[v[j]];
        const int* last = inner.data() + outer[v[j] + 1];
        const int index = static_cast<int>(std::lower_bound(first, last, v[i]) - inner.data());
        if (static_cast<int>(runs_.size()) > run_begin_[t]) {
          Run& run = runs_.back();
          if (run.local_col == j && run.local_row + run.len == i && run.value + run.len == index) {
            ++run.len;
            continue;
          }
        }
        runs_.push_back({i, j, 1, index, false});
      }
    }
    run_begin_.push_back(static_cast<int>(runs_.size()));
    touches_controls_.push_back(controls ? 1 : 0);
    contiguous_.push_back(-1);
  }
}

}  // namespace snapthread::internal
