// End-to-end: snapthread-viewer runs as a real process on its own Xvfb, receives shapes over
// udpm loopback, and its screenshot must show the thread where the camera projects it.
#include <atomic>
#include <cstdio>
#include <mutex>
#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <thread>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "app/exit_codes.h"
#include "messages/pose_mapping.h"
#include "grasp_publisher.h"
#include "hud_layout.h"
#include "marker_colors.h"
#include "snapthread/device_state_t.hpp"
#include "scene/scene.h"
#include "orbit_camera.h"
#include "auth/credential.h"
#include "auth/credential_file.h"
#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"
#include "messages/channels.h"
#include "messages/subscribe.h"
#include "spline.h"
#include "png_image.h"
#include "test_support.h"
#include "arc_session.h"

namespace snapthread::viewer_test {
namespace {

using namespace test_support;  // the shared fixtures (tests/support)

using viewer::CatmullRomCurve;
using viewer::OrbitCamera;
using viewer::Point3;

// The viewer on an observer credential shows the live thread.
TEST(ViewerScreenshotTest, ShowsTheThreadAlongTheProjectedArc) {
  const std::string session = UniqueSession("VIEWARC");
  const std::string dir = FreshTempDir("viewer-arc");
  ShapePublisher publisher(session, /*with_garbage=*/false);
  const std::string observer = WriteCredential(dir, publisher.root(), auth::Role::kObserver);
  ASSERT_TRUE(publisher.Start()) << "LCM publisher failed on " << kLoopbackUrl
                                 << " (no multicast route? see deploy/multicast-route.sh)";
  const ViewerRun run = RunViewerScreenshot(session, dir, 5, 30.0, observer);
  publisher.Stop();
  ASSERT_TRUE(run.result.exited) << "viewer did not exit; stderr:\n" << run.result.err;
  ASSERT_EQ(run.result.exit_code, 0) << run.result.out << run.result.err;
  EXPECT_NE(run.result.out.find("wrote " + run.png), std::string::npos) << run.result.out;
  Image img;
  std::string error;
  ASSERT_TRUE(ReadPng(run.png, &img, &error)) << error;
  ExpectArcDrawn(img);
}
TEST(ViewerScreenshotTest, MalformedShapePacketsAreDroppedAndCounted) {
  const std::string session = UniqueSession("VIEWBAD");
  const std::string dir = FreshTempDir("viewer-bad");
  ShapePublisher publisher(session, /*with_garbage=*/true);
  ASSERT_TRUE(publisher.Start());
  // 20 valid shapes: by then garbage of every kind has arrived between them.
  const ViewerRun run = RunViewerScreenshot(session, dir, 20, 30.0);
  publisher.Stop();
  ASSERT_TRUE(run.result.exited) << run.result.err;
  ASSERT_EQ(run.result.exit_code, 0) << "viewer crashed or failed on malformed packets:\n"
                                     << run.result.out << run.result.err;
  // "... after N shapes, B bad messages": the bad ones were seen and dropped.
  const auto at = run.result.out.find("shapes, ");
  ASSERT_NE(at, std::string::npos) << run.result.out;
  const long bad = std::atol(run.result.out.c_str() + at + 8);
  EXPECT_GE(bad, 5) << run.result.out;
  EXPECT_GE(publisher.garbage_sent(), bad);
  Image img;
  std::string error;
  ASSERT_TRUE(ReadPng(run.png, &img, &error)) << error;
  ExpectArcDrawn(img);  // the valid shapes still render correctly
}

// Mean colour of the drawn path pixels (outside the overlays).
Eigen::Vector3d PathColour(const Image& img) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const Eigen::Vector2d& q : ArcPixelPath(ArcCamera())) {
    if (InOverlay(q.x(), q.y(), 4)) continue;
    const uint8_t* c = img.At(int(std::lround(q.x())), int(std::lround(q.y())));
    sum += Eigen::Vector3d(c[0], c[1], c[2]);
    n++;
  }
  return n > 0 ? Eigen::Vector3d(sum / n) : sum;
}

// The solver state is colour coded: regular threads are drawn pale blue, snapped ones red.
TEST(ViewerScreenshotTest, SolverStateIsColourCoded) {
  Eigen::Vector3d colour[2];
  const int8_t states[2] = {0, 2};  // force_model_t::STATUS_REGULAR, STATUS_SNAPPED
  for (int i = 0; i < 2; ++i) {
    const std::string session = UniqueSession("VIEWSTATE");
    const std::string dir = FreshTempDir("viewer-state" + std::to_string(i));
    ShapePublisher publisher(session, false, states[i]);
    ASSERT_TRUE(publisher.Start());
    const ViewerRun run = RunViewerScreenshot(session, dir, 3, 30.0);
    publisher.Stop();
    ASSERT_EQ(run.result.exit_code, 0) << run.result.err;
    Image img;
    std::string error;
    ASSERT_TRUE(ReadPng(run.png, &img, &error)) << error;
    ExpectArcDrawn(img);
    colour[i] = PathColour(img);
  }
  EXPECT_GT(colour[0].z(), colour[0].x() + 40) << "regular: " << colour[0].transpose();
  EXPECT_GT(colour[1].x(), colour[1].y() + 80) << "snapped: " << colour[1].transpose();
  EXPECT_GT(colour[1].x(), colour[1].z() + 80) << "snapped: " << colour[1].transpose();
}

// Issue 15: two grasps (the arc's end and its apex, each with its force) and one active
// contact between two points of the arc at 40 and 50 degrees.
const Point3 kGraspA(-1.0, 0.0, 0.0), kGraspB(0.0, 1.0, 0.0);
const Point3 kContactA(std::cos(0.7), std::sin(0.7), 0.0), kContactB(std::cos(0.87), std::sin(0.87), 0.0);

void AddGraspsAndContact(thread_shape_t* s) {
  s->grasp_names = "left,right";
  s->num_grasps = 2;
  // The apex's force points down into the arc, the larger one: its arrow has full length.
  s->grasps = {{kGraspA.x(), kGraspA.y(), kGraspA.z(), 0.0, -0.5, 0.0},
               {kGraspB.x(), kGraspB.y(), kGraspB.z(), 0.0, -1.0, 0.0}};
  s->num_contacts = 1;
  s->contacts = {{kContactA.x(), kContactA.y(), kContactA.z(), kContactB.x(), kContactB.y(),
                  kContactB.z()}};
  s->knot = "unknot";
}

// The pixel's colour is `want` (a marker's flat colour, lit face-on) within `tol` levels.
::testing::AssertionResult HasColour(const Image& img, const Eigen::Vector2d& at,
                                     const viewer::Rgb& want, int tol) {
  const uint8_t* c = img.At(int(std::lround(at.x())), int(std::lround(at.y())));
  for (int i = 0; i < 3; ++i) {
    if (std::abs(c[i] - int(std::lround(255 * want[i]))) > tol) {
      return ::testing::AssertionFailure()
             << "pixel (" << at.transpose() << ") is " << int(c[0]) << "," << int(c[1]) << ","
             << int(c[2]) << ", want " << (255 * want).transpose();
    }
  }
  return ::testing::AssertionSuccess();
}

TEST(ViewerScreenshotTest, DrawsEveryGraspAndTheActiveContacts) {
  const std::string session = UniqueSession("VIEWGRASPS");
  const std::string dir = FreshTempDir("viewer-grasps");
  ShapePublisher publisher(session, false, 0, AddGraspsAndContact);
  ASSERT_TRUE(publisher.Start());
  const ViewerRun run = RunViewerScreenshot(session, dir, 5, 30.0);
  publisher.Stop();
  ASSERT_EQ(run.result.exit_code, 0) << run.result.out << run.result.err;
  Image img;
  std::string error;
  ASSERT_TRUE(ReadPng(run.png, &img, &error)) << error;
  const OrbitCamera camera = ArcCamera();
  auto px = [&](const Point3& p) { return camera.ProjectToPixel(p, kWidth, kHeight); };
  // Each grasp in its own colour (the marker's centre faces the camera: fully lit), where
  // the tube alone is pale blue.
  EXPECT_TRUE(HasColour(img, px(kGraspA), viewer::GraspColor(0), 40));
  EXPECT_TRUE(HasColour(img, px(kGraspB), viewer::GraspColor(1), 40));
  // Both contact points and the middle of the segment joining them are highlighted.
  EXPECT_TRUE(HasColour(img, px(kContactA), viewer::kContactColor, 40));
  EXPECT_TRUE(HasColour(img, px(kContactB), viewer::kContactColor, 40));
  EXPECT_TRUE(HasColour(img, px(0.5 * (kContactA + kContactB)), viewer::kContactColor, 40));
  // The second grasp's force arrow runs from the apex down into the arc (the first one's,
  // half as long, along the x axis below the arc's end).
  EXPECT_TRUE(HasColour(img, px(Point3(0.0, 0.6, 0.0)), viewer::kForceArrowColor, 60));
  EXPECT_TRUE(IsBackground(img.At(int(px(Point3(0.0, 0.2, 0.0)).x()),
                                  int(px(Point3(0.0, 0.2, 0.0)).y()))));
  // A tube pixel away from every marker is the tube's colour, not a marker's.
  const Eigen::Vector2d tube = px(Point3(std::cos(2.2), std::sin(2.2), 0.0));
  EXPECT_FALSE(HasColour(img, tube, viewer::kContactColor, 40));
  EXPECT_FALSE(HasColour(img, tube, viewer::GraspColor(1), 40));
}
TEST(ViewerScreenshotTest, TimesOutWithAClearMessageWhenNothingArrives) {
  const std::string session = UniqueSession("VIEWNONE");
  const std::string dir = FreshTempDir("viewer-none");
  const SessionKeyFile key_file;
  const ViewerRun run = RunViewerScreenshot(session, dir, 1, 1.5);
  ASSERT_TRUE(run.result.exited) << run.result.err;
  EXPECT_EQ(run.result.exit_code, app::kExitTimeout);
  EXPECT_NE(run.result.err.find("timeout"), std::string::npos) << run.result.err;
  EXPECT_NE(run.result.err.find(session + "_SHAPE"), std::string::npos) << run.result.err;
}

}  // namespace
}  // namespace snapthread::viewer_test
