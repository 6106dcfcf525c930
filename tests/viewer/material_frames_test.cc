// The rod's stripe and twist colours without a display (viewer/material_frames.h,
// MeshBuilder::AppendPaintedTube, DecodeShape's frame checks).
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "material_frames.h"
#include "mesh_builder.h"
#include "shape_check.h"
#include "spline.h"

namespace snapthread::viewer {
namespace {

constexpr int kSamples = 8;

// A straight rod along +x with d1 of edge j turned by `rate` j about +x from +y.
struct Rod {
  std::vector<Point3> nodes;
  std::vector<std::vector<double>> frames;
};
Rod StraightTwisted(int edges, double rate, double twist_density) {
  Rod r;
  for (int k = 0; k <= edges; ++k) r.nodes.emplace_back(0.1 * k, 0.0, 0.0);
  for (int j = 0; j < edges; ++j) {
    r.frames.push_back({0.0, std::cos(rate * j), std::sin(rate * j), twist_density});
  }
  return r;
}

Eigen::Vector3d RingDirection(const CurveFrame& f, double angle) {
  return std::cos(angle) * f.normal + std::sin(angle) * f.Binormal();
}

// At each edge's midpoint ring the stripe points along d1; between them it turns steadily
// one way (2.5 turns in all: no flip back at ±π) and the twist is carried along.
TEST(MaterialFramesTest, StripeFollowsD1AlongAStraightTwistedRod) {
  const int edges = 12;
  const double rate = 2.5 * 2.0 * std::numbers::pi / (edges - 1);  // 1.43 rad per edge
  const Rod rod = StraightTwisted(edges, rate, 7.0);
  const std::vector<Point3> path = CatmullRomCurve(rod.nodes, kSamples);
  const std::vector<CurveFrame> curve = RotationMinimisingFrames(path);
  const MaterialRings rings = InterpolateMaterialFrames(rod.frames, kSamples, curve);
  ASSERT_EQ(rings.angle.size(), path.size());
  ASSERT_EQ(rings.twist.size(), path.size());
  for (int j = 0; j < edges; ++j) {
    const int i = j * kSamples + kSamples / 2;
    const Eigen::Vector3d d1(rod.frames[j][0], rod.frames[j][1], rod.frames[j][2]);
    EXPECT_LT((RingDirection(curve[i], rings.angle[i]) - d1).norm(), 1e-9) << "edge " << j;
    EXPECT_DOUBLE_EQ(rings.twist[i], 7.0);
  }
  for (size_t i = 1; i < path.size(); ++i) EXPECT_GE(rings.angle[i], rings.angle[i - 1]);
  EXPECT_NEAR(rings.angle.back() - rings.angle.front(), rate * (edges - 1), 1e-9);
}

// An untwisted rod bent into a planar arc, d1 towards the arc's centre on every edge: the
// stripe stays on the inside all along (d1 transported along the spline keeps its angle).
TEST(MaterialFramesTest, UntwistedArcKeepsItsStripeInside) {
  const int edges = 10;
  std::vector<Point3> nodes;
  for (int k = 0; k <= edges; ++k) {
    const double a = std::numbers::pi * k / edges;
    nodes.emplace_back(std::cos(a), std::sin(a), 0.0);
  }
  std::vector<std::vector<double>> frames;
  for (int j = 0; j < edges; ++j) {
    const Point3 mid = 0.5 * (nodes[j] + nodes[j + 1]);
    const Point3 in = -mid.normalized();
    frames.push_back({in.x(), in.y(), in.z(), 0.0});
  }
  const std::vector<Point3> path = CatmullRomCurve(nodes, kSamples);
  const std::vector<CurveFrame> curve = RotationMinimisingFrames(path);
  const MaterialRings rings = InterpolateMaterialFrames(frames, kSamples, curve);
  ASSERT_EQ(rings.angle.size(), path.size());
  for (size_t i = 0; i < path.size(); ++i) {
    const Point3 in = -Point3(path[i].x(), path[i].y(), 0.0).normalized();
    // The spline's tangent at a ring differs from its edge's by a fraction of the 18°
    // between edges, so the inside is met to within that.
    EXPECT_GT(RingDirection(curve[i], rings.angle[i]).dot(in), std::cos(0.2)) << "ring " << i;
  }
}

TEST(MaterialFramesTest, CountsThatDoNotFitGiveNothing) {
  const Rod rod = StraightTwisted(5, 0.1, 0.0);
  const std::vector<CurveFrame> curve =
      RotationMinimisingFrames(CatmullRomCurve(rod.nodes, kSamples));
  EXPECT_TRUE(InterpolateMaterialFrames(rod.frames, kSamples + 1, curve).angle.empty());
  std::vector<std::vector<double>> fewer(rod.frames.begin(), rod.frames.end() - 1);
  EXPECT_TRUE(InterpolateMaterialFrames(fewer, kSamples, curve).angle.empty());
}

// Diverging map: 0 is the tube's colour, ± blend towards the two hues, saturating at the
// full scale.
TEST(MaterialFramesTest, TwistColourMap) {
  const Rgb base(0.55f, 0.80f, 0.95f);
  EXPECT_LT((TwistColor(base, 0.0, 2.0) - base).norm(), 1e-6);
  const Rgb plus = base + kTwistBlendMax * (kTwistPositiveColor - base);
  const Rgb minus = base + kTwistBlendMax * (kTwistNegativeColor - base);
  EXPECT_LT((TwistColor(base, 2.0, 2.0) - plus).norm(), 1e-6);
  EXPECT_LT((TwistColor(base, 50.0, 2.0) - plus).norm(), 1e-6);
  EXPECT_LT((TwistColor(base, -2.0, 2.0) - minus).norm(), 1e-6);
  EXPECT_LT((TwistColor(base, 1.0, 2.0) - 0.5f * (base + plus)).norm(), 1e-6);
  // Green one way, violet the other.
  EXPECT_GT(plus.y(), plus.z() + 0.2f);
  EXPECT_GT(minus.z(), minus.y() + 0.3f);
  EXPECT_NEAR(TwistFullScale({{0, 0, 0}, {0.5, 0, 0}, {0.5, 1.5, 0}}), std::numbers::pi, 1e-12);
}

// The painted tube's stripe faces are the ones whose outward normals lie within
// ±kStripeHalfColumns columns (±22.5°) of the ring's direction `angle`.
TEST(MaterialFramesTest, PaintedTubeStripeIsTheBandAroundTheAngle) {
  const std::vector<Eigen::Vector3d> path = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  const std::vector<CurveFrame> curve = RotationMinimisingFrames(path);
  TubePaint paint;
  paint.angle = {0.3, 1.0, 1.7};
  paint.color.assign(3, Rgb(0.5f, 0.5f, 0.5f));
  paint.stripe_half_columns = kStripeHalfColumns;
  paint.stripe_color = kStripeColor;
  MeshBuilder mesh;
  mesh.AppendPaintedTube(path, curve, 0.1, kStripedTubeSides, paint);
  ASSERT_EQ(mesh.vertices().size(), size_t(2 * kStripedTubeSides * 6));
  const double half_band = 2.0 * std::numbers::pi * kStripeHalfColumns / kStripedTubeSides;
  int stripe = 0;
  for (const Vertex& v : mesh.vertices()) {
    const int ring = int(std::lround(v.position[0]));
    const Eigen::Vector3d n(v.normal[0], v.normal[1], v.normal[2]);
    const double cos_to_d1 = n.dot(RingDirection(curve[ring], paint.angle[ring]));
    const bool is_stripe = v.color[0] < 0.1f;
    stripe += is_stripe;
    if (is_stripe) {
      EXPECT_GE(cos_to_d1, std::cos(half_band) - 1e-6);
    } else {
      EXPECT_LE(cos_to_d1, std::cos(half_band) + 1e-6);
    }
  }
  EXPECT_EQ(stripe, 2 * 2 * kStripeHalfColumns * 6);
}

TEST(MaterialFramesTest, DecodeShapeChecksTheFrames) {
  thread_shape_t s{};
  s.scene = "rod";
  s.model = "rod";
  s.num_nodes = 3;
  s.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  s.num_frames = 2;
  s.frames = {{0, 1, 0, 0.5}, {0, 0, 1, 0.5}};
  auto decode = [](const thread_shape_t& msg, std::string* why) {
    std::vector<uint8_t> buf(msg.getEncodedSize());
    msg.encode(buf.data(), 0, int(buf.size()));
    thread_shape_t out;
    return DecodeShape(buf.data(), int(buf.size()), &out, why);
  };
  std::string why;
  EXPECT_TRUE(decode(s, &why)) << why;
  thread_shape_t wrong_count = s;
  wrong_count.num_frames = 1;
  wrong_count.frames.pop_back();
  EXPECT_FALSE(decode(wrong_count, &why));
  EXPECT_NE(why.find("one per edge"), std::string::npos) << why;
  thread_shape_t not_unit = s;
  not_unit.frames[1] = {0, 0, 0.5, 0.5};
  EXPECT_FALSE(decode(not_unit, &why));
  EXPECT_NE(why.find("unit"), std::string::npos) << why;
}

}  // namespace
}  // namespace snapthread::viewer
