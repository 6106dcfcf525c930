// The contact room (issue 15 items 1 and 7): segment-segment squared distance and its
// exact derivatives in every case against brute force and central differences, IPC's
// barrier against central differences, the additive CCD (two capsules pushed together
// never cross, whatever the step), and the broad phase against all pairs.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <array>
#include <cmath>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "contact/barrier.h"
#include "contact/broad_phase.h"
#include "contact/ccd.h"
#include "contact/segment_distance.h"
#include "contact/self_contact.h"

namespace snapthread::contact {
namespace {

using Pts = std::array<V3, 4>;

double Dsq(const Vec12& x) {
  return SegmentDistanceSq(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), x.segment<3>(9), nullptr, nullptr);
}

// Brute force: the minimum over a fine (s, t) grid refined by golden sections in s (the
// inner minimum over t is exact for a point and a segment).
double BruteDsq(const V3& a0, const V3& a1, const V3& b0, const V3& b1) {
  auto inner = [&](double s) {
    const V3 p = a0 + s * (a1 - a0);
    const V3 eb = b1 - b0;
    const double t = std::clamp((p - b0).dot(eb) / eb.squaredNorm(), 0.0, 1.0);
    return (p - b0 - t * eb).squaredNorm();
  };
  double best = 1e300;
  for (int k = 0; k <= 20000; ++k) best = std::min(best, inner(k / 20000.0));
  return best;
}

Vec12 Pack(const V3& a0, const V3& a1, const V3& b0, const V3& b1) {
  Vec12 x;
  x << a0, a1, b0, b1;
  return x;
}

// Configurations of each case: interior-interior (crossing skew), endpoint-edge,
// endpoint-endpoint, exactly and nearly parallel (overlapping and staggered).
std::vector<Vec12> CaseConfigurations() {
  std::vector<Vec12> out;
  out.push_back(Pack({0, 0, 0}, {1, 0, 0}, {0.4, -0.5, 0.3}, {0.6, 0.5, 0.35}));      // both free
  out.push_back(Pack({0, 0, 0}, {1, 0, 0}, {1.3, -0.5, 0.2}, {1.4, 0.5, 0.25}));      // a1 - edge b
  out.push_back(Pack({0, 0, 0}, {1, 0, 0}, {0.5, 0.2, 0.3}, {0.6, 1.0, 0.9}));        // b0 - edge a
  out.push_back(Pack({0, 0, 0}, {1, 0, 0}, {1.3, 0.4, 0.2}, {2.0, 1.0, 0.5}));        // a1 - b0
  out.push_back(Pack({0, 0, 0}, {1, 0, 0}, {0.3, 0.2, 0.1}, {1.6, 0.2, 0.1}));        // parallel, overlap
  out.push_back(Pack({0, 0, 0}, {1, 0, 0}, {0.3, 0.2, 0.1}, {1.6, 0.2, 0.1 + 1e-9})); // nearly parallel
  out.push_back(Pack({0, 0, 0}, {1, 0, 0}, {1.2, 0.2, 0.1}, {2.0, 0.2, 0.1}));        // parallel, apart
  out.push_back(Pack({0, 0, 0}, {1, 0, 0}, {0.9, 0.2, 0.1}, {-0.5, 0.21, 0.1}));      // antiparallel-ish
  return out;
}

TEST(SegmentDistance, ValueMatchesBruteForceInEveryCase) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec12> configs = CaseConfigurations();
  for (int k = 0; k < 200; ++k) {
    Vec12 x;
    for (int i = 0; i < 12; ++i) x[i] = u(rng);
    configs.push_back(x);
  }
  for (const Vec12& x : configs) {
    const double d = Dsq(x);
    const double brute = BruteDsq(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), x.segment<3>(9));
    EXPECT_LE(d, brute + 1e-12);
    EXPECT_NEAR(d, brute, 1e-7 * (1.0 + brute));
  }
}

TEST(SegmentDistance, GradientAndHessianMatchFiniteDifferencesInEveryCase) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec12> configs = CaseConfigurations();
  for (int k = 0; k < 100; ++k) {
    Vec12 x;
    for (int i = 0; i < 12; ++i) x[i] = u(rng);
    configs.push_back(x);
  }
  int cases_seen[3] = {0, 0, 0};  // free parameters: 0, 1, 2
  const double h = 1e-6;
  for (const Vec12& x : configs) {
    Vec12 g;
    Mat12 hess;
    SegmentClosest c;
    SegmentDistanceSq(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), x.segment<3>(9), &g, &hess, &c);
    ++cases_seen[(c.s_free ? 1 : 0) + (c.t_free ? 1 : 0)];
    Vec12 fd_g;
    Mat12 fd_h;
    for (int i = 0; i < 12; ++i) {
      Vec12 xp = x, xm = x;
      xp[i] += h;
      xm[i] -= h;
      fd_g[i] = (Dsq(xp) - Dsq(xm)) / (2 * h);
      Vec12 gp, gm;
      SegmentDistanceSq(xp.segment<3>(0), xp.segment<3>(3), xp.segment<3>(6), xp.segment<3>(9), &gp, nullptr);
      SegmentDistanceSq(xm.segment<3>(0), xm.segment<3>(3), xm.segment<3>(6), xm.segment<3>(9), &gm, nullptr);
      fd_h.col(i) = (gp - gm) / (2 * h);
    }
    EXPECT_TRUE(g.allFinite() && hess.allFinite()) << x.transpose();
    EXPECT_LE((hess - hess.transpose()).norm(), 1e-12 * (1.0 + hess.norm()));
    const V3 ea = x.segment<3>(3) - x.segment<3>(0), eb = x.segment<3>(9) - x.segment<3>(6);
    if (ea.cross(eb).squaredNorm() <= 1e-10 * ea.squaredNorm() * eb.squaredNorm()) {
      // Parallel and overlapping, the minimiser is a whole segment and D has a kink under
      // a tilt (either tilt brings one end closer): D is differentiable only along
      // motions that keep the segments parallel. Check the translations of each one.
      for (int seg = 0; seg < 2; ++seg) {
        for (int k = 0; k < 3; ++k) {
          Vec12 v = Vec12::Zero();
          v[6 * seg + k] = v[6 * seg + 3 + k] = 1.0;
          const double fd = (Dsq(x + h * v) - Dsq(x - h * v)) / (2 * h);
          EXPECT_NEAR(g.dot(v), fd, 1e-6 * (1.0 + std::abs(fd))) << x.transpose();
        }
      }
      continue;
    }
    EXPECT_LE((g - fd_g).norm(), 1e-6 * (1.0 + fd_g.norm())) << x.transpose();
    EXPECT_LE((hess - fd_h).norm(), 1e-5 * (1.0 + fd_h.norm())) << x.transpose();
  }
  for (int k = 0; k < 3; ++k) EXPECT_GT(cases_seen[k], 0) << "no configuration with " << k << " free parameters";
}

TEST(Barrier, IsC2AtTheActivationDistanceAndMatchesFiniteDifferences) {
  ContactParams p{.enabled = true, .radius = 0.01, .dhat = 0.005, .stiffness = 0.3};
  const Barrier b(p);
  double d1, d2;
  EXPECT_EQ(b.Value(b.ActivationSq(), &d1, &d2), 0.0);
  EXPECT_EQ(d1, 0.0);
  EXPECT_EQ(d2, 0.0);
  EXPECT_TRUE(std::isinf(b.Value(b.ContactSq(), nullptr, nullptr)));
  // Just inside activation the derivatives are tiny (continuity of b' and b'').
  b.Value(b.ActivationSq() * (1 - 1e-9), &d1, &d2);
  EXPECT_LT(std::abs(d1), 1e-6);
  for (double frac : {0.02, 0.1, 0.3, 0.6, 0.9, 0.99}) {
    const double dsq = b.ContactSq() + frac * (b.ActivationSq() - b.ContactSq());
    const double h = 1e-7 * (b.ActivationSq() - b.ContactSq());
    b.Value(dsq, &d1, &d2);
    double p1, m1;
    const double fd1 = (b.Value(dsq + h, nullptr, nullptr) - b.Value(dsq - h, nullptr, nullptr)) / (2 * h);
    b.Value(dsq + h, &p1, nullptr);
    b.Value(dsq - h, &m1, nullptr);
    const double fd2 = (p1 - m1) / (2 * h);
    EXPECT_NEAR(d1, fd1, 1e-6 * std::abs(fd1)) << frac;
    EXPECT_NEAR(d2, fd2, 1e-6 * std::abs(fd2)) << frac;
    EXPECT_LT(d1, 0.0);  // repulsive
    EXPECT_GT(d2, 0.0);  // convex
  }
}

// The smallest gap d - 2r along the straight motion sampled finely on [0, t].
double MinGapAlong(const Pts& x, const Pts& dx, double t, double two_r, int samples = 2000) {
  double best = 1e300;
  for (int k = 0; k <= samples; ++k) {
    const double tau = t * k / samples;
    const double d = std::sqrt(ClosestPoints(x[0] + tau * dx[0], x[1] + tau * dx[1], x[2] + tau * dx[2],
                                             x[3] + tau * dx[3]).distance_sq);
    best = std::min(best, d - two_r);
  }
  return best;
}

TEST(CapsuleCcd, TwoSegmentsPushedTogetherNeverCrossForAnyStepSize) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double two_r = 0.02;
  int limited = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    // Segment A along x, B skew above it, both random; B pushed through A's line by a
    // step of any size from 1e-3 to 1e6 (plus random jitter of every endpoint).
    Pts x = {V3(-0.5, 0, 0), V3(0.5, 0, 0), V3(u(rng) * 0.3, -0.5, 0.05 + 0.2 * std::abs(u(rng))),
             V3(u(rng) * 0.3, 0.5, 0.05 + 0.2 * std::abs(u(rng)))};
    for (V3& p : x) p += 0.05 * V3(u(rng), u(rng), u(rng));
    if (std::sqrt(ClosestPoints(x[0], x[1], x[2], x[3]).distance_sq) <= two_r) continue;
    const double size = std::pow(10.0, -3.0 + 9.0 * (0.5 + 0.5 * u(rng)));
    Pts dx;
    for (int k = 0; k < 4; ++k) dx[k] = size * 0.3 * V3(u(rng), u(rng), u(rng));
    dx[2].z() -= size;
    dx[3].z() -= size;
    const double gap0 = std::sqrt(ClosestPoints(x[0], x[1], x[2], x[3]).distance_sq) - two_r;
    const double t = CapsuleCcd(x[0], x[1], x[2], x[3], dx[0], dx[1], dx[2], dx[3], two_r, 0.1);
    ASSERT_GE(t, 0.0);
    ASSERT_LE(t, 1.0);
    if (t < 1.0) ++limited;
    ASSERT_GT(MinGapAlong(x, dx, t, two_r), 0.0) << "trial " << trial << " size " << size;
    // The end of the allowed step keeps a tenth of the gap.
    const double end = std::sqrt(ClosestPoints(x[0] + t * dx[0], x[1] + t * dx[1], x[2] + t * dx[2],
                                               x[3] + t * dx[3]).distance_sq) - two_r;
    EXPECT_GE(end, 0.1 * gap0 * (1 - 1e-9));
    // Progress: the bound is not zero for a pair that is apart.
    EXPECT_GT(t, 0.0);
  }
  EXPECT_GT(limited, 1000);  // most pushes would cross: the bound acted
}

TEST(CapsuleCcd, FreeMotionIsNotLimitedAndTouchingCapsulesCannotMove) {
  const V3 a0(0, 0, 0), a1(1, 0, 0), b0(0, 0, 1), b1(1, 0, 1), z(0, 0, 0);
  // A common translation changes no distance.
  EXPECT_EQ(CapsuleCcd(a0, a1, b0, b1, V3(5, 5, 5), V3(5, 5, 5), V3(5, 5, 5), V3(5, 5, 5), 0.1, 0.1), 1.0);
  // Moving apart.
  EXPECT_EQ(CapsuleCcd(a0, a1, b0, b1, z, z, V3(0, 0, 3), V3(0, 0, 3), 0.1, 0.1), 1.0);
  // Already touching.
  EXPECT_EQ(CapsuleCcd(a0, a1, b0, b1, z, z, V3(0, 0, -1), V3(0, 0, -1), 1.0, 0.1), 0.0);
}

TEST(BroadPhase, FindsExactlyTheOverlappingBoxes) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  BroadPhase bp;
  for (int round = 0; round < 20; ++round) {
    const int m = 50 + 20 * round;
    Eigen::Matrix3Xd lo(3, m), hi(3, m);
    for (int i = 0; i < m; ++i) {
      const double size = (i % 17 == 0) ? 0.5 : 0.05 * u(rng);  // a few long boxes
      for (int k = 0; k < 3; ++k) {
        lo(k, i) = u(rng) - 0.5;
        hi(k, i) = lo(k, i) + size * u(rng);
      }
    }
    // Every other round drops the pairs closer than 3 in index (a chain's neighbours).
    const int gap = round % 2 == 0 ? 1 : 3;
    std::vector<std::pair<int, int>> got;
    bp.Overlaps(lo, hi, &got, gap);
    std::vector<std::pair<int, int>> want;
    for (int i = 0; i < m; ++i) {
      for (int j = i + gap; j < m; ++j) {
        bool overlap = true;
        for (int k = 0; k < 3; ++k) overlap = overlap && std::max(lo(k, i), lo(k, j)) <= std::min(hi(k, i), hi(k, j));
        if (overlap) want.emplace_back(i, j);
      }
    }
    EXPECT_EQ(got, want) << "round " << round;
  }
}

// A chain of capsules: the step bound of the whole chain keeps every included pair apart.
TEST(SelfContact, ChainStepBoundKeepsEveryPairApart) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const ContactParams p{.enabled = true, .radius = 0.02, .dhat = 0.01, .stiffness = 1.0};
  const int m = 40;
  const SelfContact sc(p, m, 0.1);
  EXPECT_EQ(sc.MinIndexGap(), 2);
  int tested = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::Matrix3Xd from(3, m + 1), to(3, m + 1);
    // A close helix (radius 0.2, turns 0.1 apart: every turn near its neighbours), jittered.
    for (int k = 0; k <= m; ++k) {
      const double a = 0.5 * k;
      from.col(k) = V3(0.2 * std::cos(a), 0.2 * std::sin(a), 0.1 * a / (2 * M_PI)) + 0.01 * V3(u(rng), u(rng), u(rng));
    }
    if (sc.MinDistance(from) <= 2 * p.radius) continue;
    ++tested;
    const double size = std::pow(10.0, 3.0 * u(rng));
    for (int k = 0; k <= m; ++k) to.col(k) = from.col(k) + size * V3(u(rng), u(rng), u(rng));
    const double t = sc.MaxStepFraction(from, to);
    ASSERT_GE(t, 0.0);
    for (int s = 0; s <= 200; ++s) {
      const Eigen::Matrix3Xd mid = from + (t * s / 200.0) * (to - from);
      ASSERT_GT(sc.MinDistance(mid), 2 * p.radius) << "trial " << trial;
    }
  }
  EXPECT_GT(tested, 20);
}

// Contact cost against n (issue 15 item 8): energy, gradient and Hessian of every active
// pair on a close helix (each segment near the turns above and below it, so the active
// pairs grow like n). The work the broad phase leaves to the narrow phase must grow like
// n too: 16 x the segments give 16 x the candidate pairs, where all pairs would give
// 256 x. The times (best of 5) are printed, not asserted (a loaded machine).
TEST(SelfContact, CostGrowsLinearlyWithTheSegments) {
  const ContactParams p{.enabled = true, .radius = 0.02, .dhat = 0.02, .stiffness = 1.0};
  const int sizes[2] = {200, 3200};
  int pairs[2] = {0, 0}, candidates[2] = {0, 0};
  double per_call_us[2] = {0.0, 0.0};
  for (int s = 0; s < 2; ++s) {
    const int m = sizes[s];
    const SelfContact sc(p, m, 0.1);
    Eigen::Matrix3Xd nodes(3, m + 1);
    for (int k = 0; k <= m; ++k) {
      const double a = 0.5 * k;  // turns 0.05 apart: gap 0.01 < d-hat
      nodes.col(k) = V3(0.2 * std::cos(a), 0.2 * std::sin(a), 0.05 * a / (2 * M_PI));
    }
    double best = 1e300;
    for (int rep = 0; rep < 5; ++rep) {
      const auto t0 = std::chrono::steady_clock::now();
      double sum = sc.Energy(nodes);
      int count = 0;
      sc.ForEachActive(nodes, true, [&](int, int, const Vec12& g, const Mat12& h) {
        sum += g[0] + h(0, 0);
        ++count;
      });
      best = std::min(best, std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
      pairs[s] = count;
      candidates[s] = sc.CandidatePairs();
      ASSERT_TRUE(std::isfinite(sum));
    }
    per_call_us[s] = best;
  }
  std::printf("self-contact E + E_x + E_xx: n = %d: %.0f us (%d active of %d candidate pairs); "
              "n = %d: %.0f us (%d of %d)\n",
              sizes[0], per_call_us[0], pairs[0], candidates[0], sizes[1], per_call_us[1], pairs[1], candidates[1]);
  EXPECT_GT(pairs[0], sizes[0] / 2);
  EXPECT_LE(candidates[1], 20 * candidates[0]);
  EXPECT_LE(pairs[1], 20 * pairs[0]);
}

}  // namespace
}  // namespace snapthread::contact
