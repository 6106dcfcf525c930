// common/topology: knot types of curves whose type is known, under rotation and noise.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "topology/alexander.h"
#include "topology/closure.h"
#include "topology/identify_knot.h"

namespace snapthread::topology {
namespace {

using Curve = std::vector<Eigen::Vector3d>;
using Param = std::function<Eigen::Vector3d(double)>;

// n samples of f on [t0, t1) (closed curves) or [t0, t1] (open).
Curve Sample(const Param& f, double t0, double t1, int n, bool open) {
  Curve c;
  for (int i = 0; i < n; ++i) c.push_back(f(t0 + (t1 - t0) * i / (open ? n - 1 : n)));
  return c;
}

// The (p, q) torus knot on a torus of radii 2 and 1: (2,3) trefoil, (2,5) cinquefoil.
Param Torus(int p, int q) {
  return [p, q](double t) {
    const double r = 2.0 + std::cos(q * t);
    return Eigen::Vector3d(r * std::cos(p * t), r * std::sin(p * t), std::sin(q * t));
  };
}

Eigen::Vector3d FigureEight(double t) {
  const double r = 2.0 + std::cos(2 * t);
  return {r * std::cos(3 * t), r * std::sin(3 * t), std::sin(4 * t)};
}

Curve Mirror(Curve c) {
  for (auto& p : c) p.z() = -p.z();
  return c;
}

Curve Rotated(Curve c, std::mt19937& rng, double noise) {
  std::normal_distribution<double> g(0.0, 1.0);
  const Eigen::Quaterniond q =
      Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized();
  for (auto& p : c) p = q * p + noise * Eigen::Vector3d(g(rng), g(rng), g(rng));
  return c;
}

// A torus knot cut open at its outermost point (t = 0), ends pulled far apart along ±y:
// an overhand knot in an open rope.
Curve OpenKnot(const Param& f, int n, double pull) {
  const double gap = 0.05;
  Curve c{{4.0, -pull, 0.0}, {4.0, -1.0, 0.0}};
  for (const auto& p : Sample(f, -(2 * M_PI - gap), -gap, n, true)) c.push_back(p);
  c.push_back({4.0, 1.0, 0.0});
  c.push_back({4.0, pull, 0.0});
  return c;
}

// Two copies of a knot joined by a band (connected sum); `mirror_second` for the square knot.
Curve ConnectedSum(const Param& f, bool mirror_second) {
  const double gap = 0.05;
  Curve a = Sample(f, gap, 2 * M_PI - gap, 200, true);
  Curve b = Sample(f, gap, 2 * M_PI - gap, 200, true);
  if (mirror_second) b = Mirror(b);
  Curve c = a;
  // The second copy turned half a turn about z and moved along x: its gap faces the first's.
  for (const auto& p : b) c.push_back({8.0 - p.x(), -p.y(), p.z()});
  return c;
}

TEST(TopologyTest, ClosedCurvesOfKnownType) {
  struct Case {
    Curve curve;
    const char* name;
    std::int64_t det;
    std::vector<std::int64_t> alexander;
  };
  const Case cases[] = {
      {Sample(Torus(1, 0), 0, 2 * M_PI, 100, false), "unknot", 1, {1}},
      {Sample(Torus(2, 3), 0, 2 * M_PI, 200, false), "trefoil", 3, {1, -1, 1}},
      {Mirror(Sample(Torus(2, 3), 0, 2 * M_PI, 200, false)), "trefoil", 3, {1, -1, 1}},
      {Sample(FigureEight, 0, 2 * M_PI, 300, false), "figure-eight", 5, {-1, 3, -1}},
      {Sample(Torus(2, 5), 0, 2 * M_PI, 300, false), "cinquefoil", 5, {1, -1, 1, -1, 1}},
      {ConnectedSum(Torus(2, 3), false), "granny or square", 9, {1, -2, 3, -2, 1}},
      {ConnectedSum(Torus(2, 3), true), "granny or square", 9, {1, -2, 3, -2, 1}},
      {[] {
         Curve c = Sample(Torus(2, 3), 0.05, 2 * M_PI - 0.05, 200, true);
         for (const auto& p : Sample(FigureEight, 0.05, 2 * M_PI - 0.05, 300, true))
           c.push_back({8.0 - p.x(), -p.y(), p.z()});
         return c;
       }(),
       "trefoil # figure-eight", 15, {-1, 4, -5, 4, -1}},
  };
  for (const Case& c : cases) {
    for (bool simplify : {true, false}) {
      KnotOptions options;
      options.simplify = simplify;
      const KnotInfo k = IdentifyClosedKnot(c.curve, options);
      ASSERT_TRUE(k.ok) << c.name << ": " << k.error;
      EXPECT_EQ(k.name, c.name) << "simplify " << simplify;
      EXPECT_EQ(k.determinant, c.det) << c.name;
      EXPECT_EQ(k.alexander, c.alexander) << c.name;
      EXPECT_EQ(k.agreeing, options.projections) << c.name;
    }
  }
}

TEST(TopologyTest, OpenRopesClosedFarAway) {
  EXPECT_EQ(IdentifyKnot(OpenKnot(Torus(2, 3), 200, 30.0)).name, "trefoil");
  EXPECT_EQ(IdentifyKnot(Mirror(OpenKnot(Torus(2, 3), 200, 30.0))).name, "trefoil");
  EXPECT_EQ(IdentifyKnot(OpenKnot(FigureEight, 300, 30.0)).name, "figure-eight");
  EXPECT_EQ(IdentifyKnot(OpenKnot(Torus(2, 5), 300, 5.0)).name, "cinquefoil");
  // A straight rope and a coiled one (20 turns, many crossings in most projections).
  EXPECT_EQ(IdentifyKnot(Sample([](double t) { return Eigen::Vector3d(t, 0.1 * t, 0); },
                                0, 1, 50, true)).name,
            "unknot");
  const Curve helix = Sample(
      [](double t) { return Eigen::Vector3d(std::cos(t), std::sin(t), 0.05 * t); }, 0,
      40 * M_PI, 1000, true);
  EXPECT_EQ(IdentifyKnot(helix).name, "unknot");
  // A flat spiral (curve2d's case): its inner end's way out crosses it in its own plane.
  const Curve spiral = Sample(
      [](double t) { return Eigen::Vector3d((1 + t) * std::cos(t), (1 + t) * std::sin(t), 0); },
      0, 6 * M_PI, 300, true);
  EXPECT_EQ(IdentifyKnot(spiral).name, "unknot");
  // Unsimplified, the projections have too many crossings for the polynomial; the
  // determinant is still exact.
  KnotOptions raw;
  raw.simplify = false;
  const KnotInfo coiled = IdentifyKnot(helix, raw);
  EXPECT_GT(coiled.crossings, kMaxPolynomialCrossings);
  EXPECT_EQ(coiled.determinant, 1);
  EXPECT_TRUE(coiled.alexander.empty());
  // Six turns: a dozen or more crossings, polynomial and all.
  const KnotInfo six = IdentifyKnot(
      Sample([](double t) { return Eigen::Vector3d(std::cos(t), std::sin(t), 0.2 * t); }, 0,
             12 * M_PI, 300, true),
      raw);
  EXPECT_EQ(six.name, "unknot");
  EXPECT_GT(six.crossings, 10);
}

TEST(TopologyTest, InvariantUnderRotationAndNoise) {
  std::mt19937 rng(7);
  const struct {
    Curve curve;
    const char* name;
  } cases[] = {
      {OpenKnot(Torus(2, 3), 200, 30.0), "trefoil"},
      {OpenKnot(FigureEight, 300, 30.0), "figure-eight"},
      {Sample(Torus(2, 5), 0, 2 * M_PI, 300, false), "cinquefoil"},
      {Sample([](double t) { return Eigen::Vector3d(std::cos(t), std::sin(t), 0.05 * t); },
              0, 20 * M_PI, 500, true),
       "unknot"},
  };
  for (const auto& c : cases) {
    for (int trial = 0; trial < 10; ++trial) {
      const KnotInfo k = IdentifyKnot(Rotated(c.curve, rng, 1e-3));
      EXPECT_EQ(k.name, c.name) << "trial " << trial;
    }
  }
}

TEST(TopologyTest, BadInputIsReportedNotThrown) {
  Curve c = Sample(Torus(2, 3), 0, 2 * M_PI, 50, true);
  c[10].x() = NAN;
  KnotInfo k = IdentifyKnot(c);
  EXPECT_FALSE(k.ok);
  EXPECT_FALSE(k.error.empty());
  EXPECT_FALSE(IdentifyKnot(Curve{}).ok);
  EXPECT_FALSE(IdentifyKnotXyz(std::vector<double>{1.0, 2.0}).ok);
  EXPECT_EQ(IdentifyKnotXyz(std::vector<double>{0, 0, 0, 1, 0, 0, 2, 1, 0}).name, "unknot");
  // All nodes at one point: a point is unknotted.
  EXPECT_EQ(IdentifyKnot(Curve(5, Eigen::Vector3d(1, 2, 3))).name, "unknot");
}

// Closure: the far points lie on the sphere of three times the radius.
TEST(TopologyTest, ClosureReachesTheFarSphere) {
  const Curve open = OpenKnot(Torus(2, 3), 100, 10.0);
  const Curve closed = CloseFarAway(open);
  ASSERT_GT(closed.size(), open.size() + 1);
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double r = 0;
  for (const auto& p : open) c += p;
  c /= open.size();
  for (const auto& p : open) r = std::max(r, (p - c).norm());
  for (std::size_t i = open.size(); i < closed.size(); ++i)
    EXPECT_NEAR((closed[i] - c).norm(), 3 * r, 1e-9 * r);
}

// Cost at n = 1000 (the brief: a few ms). Printed; the bound only catches a blow-up.
TEST(TopologyTest, CostAtAThousandNodes) {
  const Curve cases[] = {OpenKnot(Torus(2, 3), 1000, 30.0),
                         Sample([](double t) {
                           return Eigen::Vector3d(std::cos(t), std::sin(t), 0.05 * t);
                         }, 0, 40 * M_PI, 1000, true)};
  for (const Curve& c : cases) {
    std::vector<double> ms;
    for (int i = 0; i < 15; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      const KnotInfo k = IdentifyKnot(c);
      ms.push_back(std::chrono::duration<double, std::milli>(
                       std::chrono::steady_clock::now() - t0).count());
      ASSERT_TRUE(k.ok);
    }
    std::sort(ms.begin(), ms.end());
    std::printf("IdentifyKnot n=%zu: median %.3f ms, max %.3f ms\n", c.size(), ms[7],
                ms.back());
    EXPECT_LT(ms[7], 50.0);
  }
}

}  // namespace
}  // namespace snapthread::topology
