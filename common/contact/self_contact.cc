#include "contact/self_contact.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "contact/ccd.h"

namespace snapthread::contact {

SelfContact::SelfContact(const ContactParams& params, int segments, double rest_length)
    : params_(params), barrier_(params), segments_(segments) {
  // Excluded: (j - i - 1) ℓ ≤ 2r, and always neighbours.
  min_gap_ = 2;
  while ((min_gap_ - 1) * rest_length <= params_.ContactDistance()) ++min_gap_;
  lo_.resize(3, segments_);
  hi_.resize(3, segments_);
}

void SelfContact::FindPairs(const Eigen::Matrix3Xd& nodes, const Eigen::Matrix3Xd* to, double reach,
                            BroadPhase* broad, Eigen::Matrix3Xd* lo, Eigen::Matrix3Xd* hi,
                            std::vector<std::pair<int, int>>* pairs) const {
  const double half = 0.5 * reach;
  if (lo->cols() != segments_) {
    lo->resize(3, segments_);
    hi->resize(3, segments_);
  }
  for (int i = 0; i < segments_; ++i) {
    Eigen::Vector3d l = nodes.col(i).cwiseMin(nodes.col(i + 1));
    Eigen::Vector3d h = nodes.col(i).cwiseMax(nodes.col(i + 1));
    if (to != nullptr) {
      l = l.cwiseMin(to->col(i)).cwiseMin(to->col(i + 1));
      h = h.cwiseMax(to->col(i)).cwiseMax(to->col(i + 1));
    }
    lo->col(i) = l.array() - half;
    hi->col(i) = h.array() + half;
  }
  broad->Overlaps(*lo, *hi, pairs, min_gap_);  // included pairs only: j - i >= min_gap_
}

void SelfContact::FindPairs(const Eigen::Matrix3Xd& nodes, const Eigen::Matrix3Xd* to, double reach) const {
  if (to == nullptr && cache_valid_ && reach == cached_reach_ && cached_nodes_.cols() == nodes.cols() &&
      std::equal(nodes.data(), nodes.data() + nodes.size(), cached_nodes_.data())) {
    return;
  }
  FindPairs(nodes, to, reach, &broad_, &lo_, &hi_, &pairs_);
  cache_valid_ = to == nullptr;
  if (cache_valid_) {
    cached_nodes_ = nodes;  // no allocation once sized
    cached_reach_ = reach;
  }
}

double SelfContact::Energy(const Eigen::Matrix3Xd& nodes) const {
  FindPairs(nodes, nullptr, params_.ActivationDistance());
  double e = 0.0;
  for (const auto& [i, j] : pairs_) {
    const double dsq = ClosestPoints(nodes.col(i), nodes.col(i + 1), nodes.col(j), nodes.col(j + 1)).distance_sq;
    e += barrier_.Value(dsq, nullptr, nullptr);
  }
  return e;
}

void SelfContact::PairsWithin(const Eigen::Matrix3Xd& nodes, double distance,
                              std::vector<std::pair<int, int>>* out) const {
  FindPairs(nodes, nullptr, distance);
  out->clear();
  const double limit = distance * distance;
  for (const auto& [i, j] : pairs_) {
    if (ClosestPoints(nodes.col(i), nodes.col(i + 1), nodes.col(j), nodes.col(j + 1)).distance_sq < limit)
      out->emplace_back(i, j);
  }
}

double SelfContact::MaxStepFraction(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to) const {
  // Pairs whose swept boxes come within the activation distance: any other pair stays
  // farther apart than 2r + d̂ (so it keeps its gap above d̂ > 0).
  FindPairs(from, &to, params_.ActivationDistance());
  double alpha = 1.0;
  for (const auto& [i, j] : pairs_) {
    const double t = CapsuleCcd(from.col(i), from.col(i + 1), from.col(j), from.col(j + 1),
                                to.col(i) - from.col(i), to.col(i + 1) - from.col(i + 1),
                                to.col(j) - from.col(j), to.col(j + 1) - from.col(j + 1),
                                params_.ContactDistance(), kKeep, alpha);
    alpha = std::min(alpha, t);
    if (alpha <= 0.0) return 0.0;
  }
  return alpha;
}

std::vector<ContactPoint> SelfContact::ActivePairs(const Eigen::Matrix3Xd& nodes) const {
  std::vector<ContactPoint> out;
  BroadPhase broad;
  Eigen::Matrix3Xd lo, hi;
  std::vector<std::pair<int, int>> pairs;
  FindPairs(nodes, nullptr, params_.ActivationDistance(), &broad, &lo, &hi, &pairs);
  for (const auto& [i, j] : pairs) {
    const SegmentClosest c = ClosestPoints(nodes.col(i), nodes.col(i + 1), nodes.col(j), nodes.col(j + 1));
    if (c.distance_sq >= barrier_.ActivationSq()) continue;
    ContactPoint p;
    p.segment_a = i;
    p.segment_b = j;
    p.point_a = nodes.col(i) + c.s * (nodes.col(i + 1) - nodes.col(i));
    p.point_b = nodes.col(j) + c.t * (nodes.col(j + 1) - nodes.col(j));
    p.distance = std::sqrt(c.distance_sq);
    out.push_back(p);
  }
  return out;
}

double SelfContact::MinDistance(const Eigen::Matrix3Xd& nodes, int* seg_a, int* seg_b) const {
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < segments_; ++i) {
    for (int j = i + min_gap_; j < segments_; ++j) {
      const double d = std::sqrt(
          ClosestPoints(nodes.col(i), nodes.col(i + 1), nodes.col(j), nodes.col(j + 1)).distance_sq);
      if (d < best) {
        best = d;
        if (seg_a != nullptr) *seg_a = i;
        if (seg_b != nullptr) *seg_b = j;
      }
    }
  }
  return best;
}

}  // namespace snapthread::contact
