// Unit tests of the viewer's GL-free parts: spline, camera, device mapping inverse.
#include <cmath>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "messages/pose_mapping.h"
#include "messages/subscribe.h"
#include "snapthread/device_state_t.hpp"

#include "grasp_publisher.h"
#include "orbit_camera.h"
#include "shape_check.h"
#include "spline.h"

namespace snapthread::viewer {
namespace {

TEST(SplineTest, InterpolatesEveryNodeAndStaysNearTheChord) {
  std::vector<Point3> nodes;
  for (int i = 0; i < 7; ++i) nodes.emplace_back(i * 0.5, std::sin(i * 0.7), 0.1 * i * i);
  const int k = 6;
  const std::vector<Point3> c = CatmullRomCurve(nodes, k);
  ASSERT_EQ(c.size(), size_t((nodes.size() - 1) * k + 1));
  for (size_t i = 0; i < nodes.size(); ++i) {
    EXPECT_LT((c[i * k] - nodes[i]).norm(), 1e-12) << "node " << i;
  }
  // Centripetal Catmull-Rom does not overshoot wildly: each sample lies within one segment
  // length of its segment.
  for (size_t i = 0; i + 1 < nodes.size(); ++i) {
    const double seg = (nodes[i + 1] - nodes[i]).norm();
    for (int j = 0; j < k; ++j) {
      EXPECT_LT((c[i * k + j] - nodes[i]).norm(), 1.5 * seg);
    }
  }
}

TEST(SplineTest, StraightNodesGiveAStraightCurve) {
  std::vector<Point3> nodes = {{0, 0, 0}, {1, 1, 0}, {3, 3, 0}, {3.5, 3.5, 0}};
  for (const auto& p : CatmullRomCurve(nodes, 10)) EXPECT_NEAR(p.x(), p.y(), 1e-12);
}

TEST(OrbitCameraTest, FitCentresTheBoxAndPixelRayInvertsProjection) {
  OrbitCamera cam;
  cam.Fit({-1, 0, 0}, {1, 1, 0}, 640.0 / 480.0);
  const Eigen::Vector2d c = cam.ProjectToPixel({0, 0.5, 0}, 640, 480);
  EXPECT_NEAR(c.x(), 320, 1e-6);
  EXPECT_NEAR(c.y(), 240, 1e-6);
  // +x right, +y up on screen at yaw = pitch = 0.
  EXPECT_GT(cam.ProjectToPixel({1, 0.5, 0}, 640, 480).x(), 320);
  EXPECT_LT(cam.ProjectToPixel({0, 1, 0}, 640, 480).y(), 240);
  cam.Orbit(0.4, -0.3);
  const Eigen::Vector3d p(0.3, -0.7, 0.2);
  const Eigen::Vector2d px = cam.ProjectToPixel(p, 640, 480);
  Eigen::Vector3d o, d;
  cam.PixelRay(px.x(), px.y(), 640, 480, &o, &d);
  const Eigen::Vector3d to_p = p - o;
  EXPECT_LT((to_p - to_p.dot(d) * d).norm(), 1e-9);  // p lies on the ray
}

TEST(GraspMappingTest, ModelToDeviceInvertsTheSceneMapping) {
  DeviceMapping m;
  m.model_units_per_metre = 50.0;
  m.model_origin = {1.0, -2.0, 0.5};
  const Eigen::Vector3d model(3.0, 0.25, -1.0);
  const Eigen::Vector3d dev = messages::ModelPointToDevice(m, model);
  EXPECT_NEAR(dev.x(), 2.0 / 50.0, 1e-15);
  EXPECT_LT((messages::DeviceToModelPoint(m, dev) - model).norm(), 1e-12);
}

// Receives device_state_t on one channel (memq: same process, synchronous handle()).
struct PoseSink {
  std::vector<device_state_t> poses;
  void On(const lcm::ReceiveBuffer*, const std::string&, const device_state_t* msg) {
    poses.push_back(*msg);
  }
};

TEST(GraspMappingTest, PublisherSendsDeviceMetresOnTheSessionChannel) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  PoseSink sink;
  messages::Subscribe<&PoseSink::On>(lcm, "GRASPTEST_DEVICE_STATE", &sink);
  DeviceMapping m;
  m.model_units_per_metre = 100.0;
  m.model_origin = {0.5, 0.0, 0.0};
  GraspPublisher publisher(&lcm, "GRASPTEST", m);
  ASSERT_TRUE(publisher.Publish({2.5, -1.0, 0.0}, true));
  ASSERT_TRUE(publisher.Publish({3.0, -1.5, 0.0}, false));
  // A non-finite drag target is refused, never sent.
  EXPECT_FALSE(publisher.Publish({std::nan(""), 0.0, 0.0}, true));
  while (lcm.handleTimeout(0) > 0) {
  }
  ASSERT_EQ(sink.poses.size(), 2u);
  const device_state_t& a = sink.poses[0];
  EXPECT_NEAR(a.position[0], 0.02, 1e-15);  // (2.5 - 0.5) / 100 m
  EXPECT_NEAR(a.position[1], -0.01, 1e-15);
  EXPECT_NEAR(a.position[2], 0.0, 1e-15);
  EXPECT_EQ(a.buttons, 1);
  EXPECT_EQ(a.orientation[0], 1.0);
  EXPECT_EQ(a.device_id, "viewer-mouse");
  EXPECT_EQ(sink.poses[1].seq, a.seq + 1);
  EXPECT_EQ(sink.poses[1].buttons, 0);
  EXPECT_GE(sink.poses[1].utime, a.utime);
}

TEST(ShapeCheckTest, RefusesEmptyAndGarbageBuffers) {
  thread_shape_t s;
  std::string why;
  const uint8_t junk[64] = {1, 2, 3};
  EXPECT_FALSE(DecodeShape(junk, sizeof junk, &s, &why));
  EXPECT_FALSE(why.empty());
  thread_shape_t empty{};
  empty.num_nodes = 0;
  std::vector<uint8_t> buf(empty.getEncodedSize());
  empty.encode(buf.data(), 0, int(buf.size()));
  EXPECT_FALSE(DecodeShape(buf.data(), int(buf.size()), &s, &why));
}

}  // namespace
}  // namespace snapthread::viewer
