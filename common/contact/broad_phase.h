// Broad phase: which axis-aligned boxes overlap, in O(m + pairs) for m boxes of similar
// size, through a uniform grid hashed into a table (counting sort, no search trees).
//
// The cell size is the mean box extent (at least 1e-12 of the scene), every box goes
// into each cell it covers, and a pair is reported once: in the cell that holds the
// lower corner of the two boxes' intersection (floor is monotone, so that cell is the
// larger of the two boxes' lower cells on each axis: integer comparisons only). When
// boxes span very many cells (one long swept box), the cell size doubles until the
// entries stay below 16 m. Boxes of a chain overlap their neighbours along it: pairs
// closer in index than `min_index_gap` are dropped before any test. The scratch vectors
// keep their capacity, so a warm broad phase does not allocate.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace snapthread::contact {

class BroadPhase {
 public:
  // Pairs (i < j, j - i >= min_index_gap) of boxes [lo_i, hi_i] (columns of 3 x m
  // matrices) that overlap, written to *pairs (cleared first), sorted by (i, j).
  void Overlaps(const Eigen::Matrix3Xd& lo, const Eigen::Matrix3Xd& hi,
                std::vector<std::pair<int, int>>* pairs, int min_index_gap = 1);

 private:
  struct Entry {
    std::int64_t cell[3];
    int box;
  };
  // Overlaps' steps, in order: every box's cells into entries_ (the cell size doubled
  // while a box spans too many); the entries bucketed by cell hash and the overlapping
  // pairs of each shared lower-corner cell; the pairs sorted by (i, j).
  void FillCells(const Eigen::Matrix3Xd& lo, const Eigen::Matrix3Xd& hi);
  void FindPairs(const Eigen::Matrix3Xd& lo, const Eigen::Matrix3Xd& hi, std::vector<std::pair<int, int>>* pairs,
                 int min_index_gap);
  void SortPairs(int m, std::vector<std::pair<int, int>>* pairs);
  std::vector<Entry> entries_;
  std::vector<Entry> sorted_;
  std::vector<int> bucket_start_;
  std::vector<std::int64_t> low_cell_;  // 3 per box: the cell of its lower corner
  std::vector<int> pair_start_;         // the pairs' counting sort by i
  std::vector<std::pair<int, int>> sorted_pairs_;
};

}  // namespace snapthread::contact
