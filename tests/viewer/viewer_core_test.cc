// Unit tests of the viewer's GL-free parts: spline, camera, device mapping inverse.
#include <cmath>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "messages/pose_mapping.h"
#include "messages/subscribe.h"
#include "snapthread/device_state_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

#include <cstring>
#include <vector>

#include "auth/credential.h"
#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "grasp_publisher.h"
#include "observer_check.h"
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

// Driving with a device credential: every pose is tagged as that device (role, name) with
// its key's MAC, which the device key verifies and another device's does not.
TEST(GraspMappingTest, PublisherTagsPosesAsTheDevice) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  PoseSink sink;
  messages::Subscribe<&PoseSink::On>(lcm, "GRASPTAG_DEVICE_STATE", &sink);
  const auth::SessionKey root = auth::SessionKey::Generate();
  const auth::KeySet device = auth::KeySet::ForRole(root, auth::Role::kDevice, "hand");
  const auth::KeySet other = auth::KeySet::ForRole(root, auth::Role::kDevice, "left");
  GraspPublisher publisher(&lcm, "GRASPTAG", DeviceMapping{}, &device.tagger(), [] { return int64_t{77}; });
  ASSERT_TRUE(publisher.Publish({0.1, 0.2, 0.0}, true));
  while (lcm.handleTimeout(0) > 0) {
  }
  ASSERT_EQ(sink.poses.size(), 1u);
  device_state_t pose = sink.poses[0];
  EXPECT_EQ(pose.sender_role, static_cast<int8_t>(auth::Role::kDevice));
  EXPECT_EQ(pose.sender_name, "hand");
  EXPECT_EQ(pose.epoch, 77);
  std::vector<uint8_t> bytes(pose.getEncodedSize());
  pose.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  EXPECT_TRUE(auth::VerifyMac(bytes.data(), bytes.size(), "GRASPTAG_DEVICE_STATE", *device.mac_key()));
  EXPECT_FALSE(auth::VerifyMac(bytes.data(), bytes.size(), "GRASPTAG_DEVICE_STATE", *other.mac_key()));
}

// msg tagged by `tagger` on `channel`, encoded.
template <class Msg>
std::vector<uint8_t> Tagged(Msg msg, const std::string& channel, const auth::Tagger& tagger) {
  EXPECT_TRUE(auth::Sign(&msg, channel, 5, 6, tagger));
  std::vector<uint8_t> bytes(msg.getEncodedSize());
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

template <class Msg>
Msg Decoded(const std::vector<uint8_t>& bytes) {
  Msg m;
  m.decode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return m;
}

// What an observer's credential accepts: the server's signature on what the server
// publishes; not a device's MAC, not another root's server, not an untagged shape. An
// untagged force model is skipped (kUnsigned), a badly signed one refused.
TEST(ObserverCheckTest, AcceptsOnlyTheSessionServersSignature) {
  const auth::SessionKey root = auth::SessionKey::Generate();
  const auth::KeySet server = auth::KeySet::FromRoot(auth::SessionKey::FromBytes(root.data(), auth::SessionKey::kBytes));
  const auth::KeySet observer =
      auth::KeySet::FromCredential(auth::IssueCredential(root, auth::Role::kObserver, "", auth::kNeverExpires));
  const auth::KeySet device = auth::KeySet::ForRole(root, auth::Role::kDevice, "hand");
  const auth::KeySet other = auth::KeySet::FromRoot(auth::SessionKey::Generate());
  const auth::PublicKey& pk = observer.server_public_key();
  auto verdict = [&](const std::vector<uint8_t>& b, const std::string& channel) {
    return CheckObserved(b.data(), b.size(), channel, Decoded<thread_shape_t>(b), pk);
  };
  thread_shape_t shape{};
  shape.num_nodes = 0;
  EXPECT_EQ(verdict(Tagged(shape, "S_SHAPE", server.tagger()), "S_SHAPE"), ObserverVerdict::kAccepted);
  EXPECT_EQ(verdict(Tagged(shape, "S_SHAPE", server.tagger()), "T_SHAPE"), ObserverVerdict::kRefused)
      << "signed for another channel";
  EXPECT_EQ(verdict(Tagged(shape, "S_SHAPE", device.tagger()), "S_SHAPE"), ObserverVerdict::kRefused);
  EXPECT_EQ(verdict(Tagged(shape, "S_SHAPE", other.tagger()), "S_SHAPE"), ObserverVerdict::kRefused);
  EXPECT_EQ(verdict(Tagged(shape, "S_SHAPE", auth::Tagger{}), "S_SHAPE"), ObserverVerdict::kRefused);
  // A server signature claiming another role is refused too.
  auth::Tagger as_device = server.tagger();
  as_device.role = auth::Role::kDevice;
  EXPECT_EQ(verdict(Tagged(shape, "S_SHAPE", as_device), "S_SHAPE"), ObserverVerdict::kRefused);

  const force_model_t model{};
  auto model_verdict = [&](const std::vector<uint8_t>& b) {
    return CheckObserved(b.data(), b.size(), "S_FORCE_MODEL", Decoded<force_model_t>(b), pk);
  };
  EXPECT_EQ(model_verdict(Tagged(model, "S_FORCE_MODEL", server.tagger())), ObserverVerdict::kAccepted);
  EXPECT_EQ(model_verdict(Tagged(model, "S_FORCE_MODEL", auth::Tagger{})), ObserverVerdict::kUnsigned);
  EXPECT_EQ(model_verdict(Tagged(model, "S_FORCE_MODEL", device.tagger())), ObserverVerdict::kUnsigned)
      << "the device's MAC only: a model between the display-rate ones";
  EXPECT_EQ(model_verdict(Tagged(model, "S_FORCE_MODEL", other.tagger())), ObserverVerdict::kRefused);
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
