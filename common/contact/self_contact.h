// Self-contact of a chain of segments (nodes p_0 .. p_m, segment i = (p_i, p_{i+1})),
// each a capsule of radius r: the barrier energy over the active segment pairs, its
// per-pair derivatives, and the continuous collision bound of a straight motion of the
// nodes. Model-agnostic: a model hands in node positions and carries the per-pair
// derivatives (12 endpoint coordinates) to its own variables.
//
// Pairs: (i, j), i < j, whose segments lie more than 2r apart along the rod at rest,
// (j - i - 1) ℓ > 2r, and never neighbours (j - i ≥ 2); nearer pairs are excluded (they
// cannot meet without bending the rod more sharply than its own thickness). A pair is
// active while its centreline distance is below 2r + d̂ (barrier.h).
//
// Cost: a broad phase over the segments' boxes (broad_phase.h) and the narrow phase on
// its pairs: O(m + pairs near contact). The scratch is mutable and keeps its capacity,
// so a warm call does not allocate; one SelfContact serves one thread.
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "contact/barrier.h"
#include "contact/broad_phase.h"
#include "contact/segment_distance.h"

namespace snapthread::contact {

// The closest points of an active pair, for drawing and status.
struct ContactPoint {
  int segment_a = 0;
  int segment_b = 0;
  Eigen::Vector3d point_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d point_b = Eigen::Vector3d::Zero();
  double distance = 0.0;  // centreline distance
};

class SelfContact {
 public:
  SelfContact() = default;
  // `segments` segments of rest length `rest_length`.
  SelfContact(const ContactParams& params, int segments, double rest_length);

  bool enabled() const { return params_.enabled; }
  const ContactParams& params() const { return params_; }
  int segments() const { return segments_; }
  // Segment pairs i < j closer than this in index never interact.
  int MinIndexGap() const { return min_gap_; }
  bool Included(int i, int j) const { return j - i >= min_gap_; }

  // Σ κ b over the active pairs; +∞ if two capsules touch or overlap.
  double Energy(const Eigen::Matrix3Xd& nodes) const;
  // Calls f(i, j, g, h) for every active pair (i, j) with the gradient g (12) and, when
  // want_h, the Hessian h (12 x 12) of its barrier energy in (p_i, p_{i+1}, p_j, p_{j+1}).
  // Returns false (after calling f for the others) if some pair touches or overlaps.
  template <class F>
  bool ForEachActive(const Eigen::Matrix3Xd& nodes, bool want_h, F&& f) const {
    FindPairs(nodes, nullptr, params_.ActivationDistance());
    bool feasible = true;
    Vec12 g, dg;
    Mat12 h;
    for (const auto& [i, j] : pairs_) {
      const SegmentClosest c = ClosestPoints(nodes.col(i), nodes.col(i + 1), nodes.col(j), nodes.col(j + 1));
      const double dsq = c.distance_sq;
      if (dsq >= barrier_.ActivationSq()) continue;
      SegmentDistanceDerivatives(nodes.col(i), nodes.col(i + 1), nodes.col(j), nodes.col(j + 1), c, &dg,
                                 want_h ? &h : nullptr);
      double d1 = 0.0, d2 = 0.0;
      barrier_.Value(dsq, &d1, &d2);
      if (!(dsq > barrier_.ContactSq())) {
        feasible = false;
        continue;
      }
      // E = B(D): E_x = B' D_x, E_xx = B'' D_x D_xᵀ + B' D_xx.
      g = d1 * dg;
      if (want_h) h = d2 * (dg * dg.transpose()) + d1 * h;
      f(i, j, g, h);
    }
    return feasible;
  }

  // The largest fraction in (0, 1] (0 if some pair already touches) of the straight
  // motion from `from` to `to` (node positions) along which no two capsules meet and
  // every pair keeps its gap above kKeep of its starting gap.
  double MaxStepFraction(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to) const;
  static constexpr double kKeep = 0.1;
  // The included pairs whose centrelines come closer than `distance`, sorted (broad
  // phase with that reach, then the exact distance). Uses the scratch above.
  void PairsWithin(const Eigen::Matrix3Xd& nodes, double distance, std::vector<std::pair<int, int>>* out) const;
  // How many included pairs the last call's broad phase passed to the narrow phase (the
  // work that must stay O(n + contacts)).
  int CandidatePairs() const { return static_cast<int>(pairs_.size()); }

  // The active pairs with their closest points (allocates: for status and drawing). Uses
  // scratch of its own, so another thread may call it while the solver's thread runs.
  std::vector<ContactPoint> ActivePairs(const Eigen::Matrix3Xd& nodes) const;
  // The smallest centreline distance over the included pairs (brute force, for tests and
  // reports), and which pair.
  double MinDistance(const Eigen::Matrix3Xd& nodes, int* seg_a = nullptr, int* seg_b = nullptr) const;

 private:
  // pairs_ = included pairs whose boxes (segment boxes, or swept boxes over `to` when
  // given) inflated by half of `reach` overlap.
  // Without `to`, the last call's pairs when the nodes and the reach are the same (the
  // energy, gradient and Hessian of one state ask for the same pairs).
  void FindPairs(const Eigen::Matrix3Xd& nodes, const Eigen::Matrix3Xd* to, double reach) const;
  void FindPairs(const Eigen::Matrix3Xd& nodes, const Eigen::Matrix3Xd* to, double reach, BroadPhase* broad,
                 Eigen::Matrix3Xd* lo, Eigen::Matrix3Xd* hi, std::vector<std::pair<int, int>>* pairs) const;

  ContactParams params_{};
  Barrier barrier_{ContactParams{}};
  int segments_ = 0;
  int min_gap_ = 2;
  mutable BroadPhase broad_;
  mutable Eigen::Matrix3Xd lo_, hi_;
  mutable std::vector<std::pair<int, int>> pairs_;
  // The nodes and reach pairs_ was found for (no `to`); cache_valid_ false after a swept call.
  mutable Eigen::Matrix3Xd cached_nodes_;
  mutable double cached_reach_ = -1.0;
  mutable bool cache_valid_ = false;
};

}  // namespace snapthread::contact
