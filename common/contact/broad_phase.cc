#include "contact/broad_phase.h"

#include <algorithm>
#include <cmath>

namespace snapthread::contact {
namespace {

std::uint64_t Hash(const std::int64_t c[3]) {
  // Odd 64-bit multipliers, then a splitmix64 finaliser: the table takes the low bits,
  // which a plain product of small cell coordinates leaves clustered.
  std::uint64_t h = static_cast<std::uint64_t>(c[0]) * 0x9E3779B97F4A7C15ULL ^
                    static_cast<std::uint64_t>(c[1]) * 0xC2B2AE3D27D4EB4FULL ^
                    static_cast<std::uint64_t>(c[2]) * 0x165667B19E3779F9ULL;
  h ^= h >> 30;
  h *= 0xBF58476D1CE4E5B9ULL;
  h ^= h >> 27;
  h *= 0x94D049BB133111EBULL;
  return h ^ (h >> 31);
}

// floor(x) as an integer, inline (std::floor is a library call without SSE4.1).
inline std::int64_t FloorToInt(double x) {
  const std::int64_t i = static_cast<std::int64_t>(x);
  return i - (static_cast<double>(i) > x ? 1 : 0);
}

}  // namespace

void BroadPhase::FillCells(const Eigen::Matrix3Xd& lo, const Eigen::Matrix3Xd& hi) {
  const int m = static_cast<int>(lo.cols());
  double extent = 0.0, scene = 0.0;
  for (int i = 0; i < m; ++i) {
    extent += (hi.col(i) - lo.col(i)).maxCoeff();
    scene = std::max({scene, lo.col(i).cwiseAbs().maxCoeff(), hi.col(i).cwiseAbs().maxCoeff()});
  }
  double cell = std::max(extent / m, 1e-12 * std::max(scene, 1.0));
  // Fill the entries; a box that spans many cells doubles the cell size.
  low_cell_.resize(3 * static_cast<size_t>(m));
  for (;;) {
    entries_.clear();
    bool too_many = false;
    const double inv = 1.0 / cell;
    for (int i = 0; i < m && !too_many; ++i) {
      std::int64_t* a = low_cell_.data() + 3 * i;
      std::int64_t b[3];
      for (int k = 0; k < 3; ++k) {
        a[k] = FloorToInt(lo(k, i) * inv);
        b[k] = FloorToInt(hi(k, i) * inv);
      }
      for (std::int64_t x = a[0]; x <= b[0] && !too_many; ++x) {
        for (std::int64_t y = a[1]; y <= b[1] && !too_many; ++y) {
          for (std::int64_t z = a[2]; z <= b[2]; ++z) {
            entries_.push_back(Entry{{x, y, z}, i});
            if (static_cast<int>(entries_.size()) > 16 * m) {
              too_many = true;
              break;
            }
          }
        }
      }
    }
    if (!too_many) break;
    cell *= 2.0;
  }
}

void BroadPhase::FindPairs(const Eigen::Matrix3Xd& lo, const Eigen::Matrix3Xd& hi,
                           std::vector<std::pair<int, int>>* pairs, int min_index_gap) {
  // Counting sort by hash bucket.
  const int count = static_cast<int>(entries_.size());
  int buckets = 1;
  while (buckets < 2 * count) buckets *= 2;
  bucket_start_.assign(buckets + 1, 0);
  for (const Entry& e : entries_) ++bucket_start_[(Hash(e.cell) & (buckets - 1)) + 1];
  for (int b = 0; b < buckets; ++b) bucket_start_[b + 1] += bucket_start_[b];
  sorted_.resize(count);
  for (const Entry& e : entries_) {
    // bucket_start_[b] advances while filling; restored below by a shift.
    sorted_[bucket_start_[Hash(e.cell) & (buckets - 1)]++] = e;
  }
  for (int b = buckets; b > 0; --b) bucket_start_[b] = bucket_start_[b - 1];
  bucket_start_[0] = 0;
  for (int b = 0; b < buckets; ++b) {
    for (int p = bucket_start_[b]; p < bucket_start_[b + 1]; ++p) {
      const Entry& e = sorted_[p];
      for (int q = p + 1; q < bucket_start_[b + 1]; ++q) {
        const Entry& f = sorted_[q];
        const int i = std::min(e.box, f.box), j = std::max(e.box, f.box);
        if (j - i < min_index_gap || e.box == f.box || e.cell[0] != f.cell[0] || e.cell[1] != f.cell[1] ||
            e.cell[2] != f.cell[2])
          continue;
        // This cell holds the intersection's lower corner (each box's lower cell is
        // floor(lo / cell), and floor is monotone), and the boxes overlap.
        const std::int64_t* ci = low_cell_.data() + 3 * i;
        const std::int64_t* cj = low_cell_.data() + 3 * j;
        bool keep = true;
        for (int k = 0; k < 3 && keep; ++k) {
          keep = std::max(ci[k], cj[k]) == e.cell[k] && std::max(lo(k, i), lo(k, j)) <= std::min(hi(k, i), hi(k, j));
        }
        if (keep) pairs->emplace_back(i, j);
      }
    }
  }
}

void BroadPhase::SortPairs(int m, std::vector<std::pair<int, int>>* pairs) {
  // Sorted by (i, j) in O(m + pairs): a counting sort by i (stable), then each i's few
  // partners by j (insertion sort; a box overlaps O(1) others).
  const int count_pairs = static_cast<int>(pairs->size());
  pair_start_.assign(m + 1, 0);
  for (const auto& pr : *pairs) ++pair_start_[pr.first + 1];
  for (int i = 0; i < m; ++i) pair_start_[i + 1] += pair_start_[i];
  sorted_pairs_.resize(count_pairs);
  for (const auto& pr : *pairs) sorted_pairs_[pair_start_[pr.first]++] = pr;
  pairs->swap(sorted_pairs_);  // both keep their capacity
  for (int i = m; i > 0; --i) pair_start_[i] = pair_start_[i - 1];
  pair_start_[0] = 0;
  for (int i = 0; i < m; ++i) {
    for (int p = pair_start_[i] + 1; p < pair_start_[i + 1]; ++p) {
      const std::pair<int, int> key = (*pairs)[p];
      int q = p - 1;
      for (; q >= pair_start_[i] && (*pairs)[q].second > key.second; --q) (*pairs)[q + 1] = (*pairs)[q];
      (*pairs)[q + 1] = key;
    }
  }
}

void BroadPhase::Overlaps(const Eigen::Matrix3Xd& lo, const Eigen::Matrix3Xd& hi,
                          std::vector<std::pair<int, int>>* pairs, int min_index_gap) {
  pairs->clear();
  const int m = static_cast<int>(lo.cols());
  if (m < 2) return;
  FillCells(lo, hi);
  FindPairs(lo, hi, pairs, min_index_gap);
  SortPairs(m, pairs);
}

}  // namespace snapthread::contact
