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

namespace snapthread::viewer_test {
namespace {

using namespace test_support;  // the shared fixtures (tests/support)

using viewer::CatmullRomCurve;
using viewer::OrbitCamera;
using viewer::Point3;

using test_support::kLoopbackLcmUrl;
constexpr const char* kLoopbackUrl = kLoopbackLcmUrl;
constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr int kNodes = 21;

// A half circle of radius 1 from (1, 0) over (0, 1) to (-1, 0), in the z = 0 plane.
std::vector<Point3> ArcNodes() {
  std::vector<Point3> nodes;
  for (int i = 0; i < kNodes; ++i) {
    const double a = M_PI * i / (kNodes - 1);
    nodes.emplace_back(std::cos(a), std::sin(a), 0.0);
  }
  return nodes;
}

thread_shape_t ArcShape(int64_t seq, int8_t status = 0) {
  thread_shape_t s{};
  s.utime = seq * 16000;
  s.seq = seq;
  s.scene = "test-arc";
  s.model = "curve2d";
  s.num_nodes = kNodes;
  for (const auto& p : ArcNodes()) s.positions.push_back({p.x(), p.y(), p.z()});
  const auto& last = s.positions.back();
  for (int i = 0; i < 3; ++i) {
    s.grasp[i] = last[i];
    s.grip_direction[i] = 0.0;  // free grip: no direction arrow
    s.force[i] = 0.0;           // no force arrow, so only the thread, clamp and grasp are drawn
    s.force_newtons[i] = 0.0;
  }
  s.status = status;
  s.snaps = 0;
  return s;
}

// A credential of `role` issued from `root`, written to `dir`; its path.
std::string WriteCredential(const std::string& dir, const auth::SessionKey& root, auth::Role role,
                            const std::string& name = "") {
  const std::string path = dir + "/" + std::string(auth::RoleToString(role)) + ".cred";
  auth::WriteCredentialFile(path, auth::IssueCredential(root, role, name, auth::kNeverExpires), true);
  return path;
}

// Publishes the arc every 20 ms (plus malformed packets, or forged shapes, when asked)
// until stopped, signed as the server (the root key of a per-test key file in
// SNAPTHREAD_KEY_FILE, an epoch announced in a signed solver status before each shape).
// The forged shapes (a straight line across the window: drawn, it would show) are MACed
// with a device key of the session, or signed by another session's server.
class ShapePublisher {
 public:
  // `decorate` adds to each shape (grasps, contacts) before it is signed.
  ShapePublisher(const std::string& session, bool with_garbage, int8_t status = 0,
                 std::function<void(thread_shape_t*)> decorate = {}, bool with_forged = false)
      : forged_(with_forged),
        channel_(messages::Channels(session).shape),
        status_channel_(messages::Channels(session).solver_status),
        garbage_(with_garbage),
        status_(status),
        decorate_(std::move(decorate)) {}
  ~ShapePublisher() { Stop(); }
  bool Start() {
    if (!lcm_.good()) return false;
    thread_ = std::thread([this] { Loop(); });
    return true;
  }
  void Stop() {
    running_ = false;
    if (thread_.joinable()) thread_.join();
  }
  int64_t garbage_sent() const { return garbage_sent_; }
  int64_t forged_sent() const { return forged_sent_; }
  int64_t epoch() const { return epoch_; }
  const auth::SessionKey& root() const { return key_file_.key(); }

 private:
  void Loop() {
    std::mt19937 rng(42);
    int64_t seq = 0;
    while (running_) {
      if (garbage_) PublishGarbage(seq, &rng);
      solver_status_t st{};
      st.seq = seq;
      st.scene = "test-arc";
      st.method = "newton";
      st.status = status_;
      if (auth::Sign(&st, status_channel_, epoch_, auth_seq_.Next(), server_.tagger())) {
        lcm_.publish(status_channel_, &st);
      }
      thread_shape_t s = ArcShape(++seq, status_);
      if (decorate_) decorate_(&s);
      if (auth::Sign(&s, channel_, epoch_, auth_seq_.Next(), server_.tagger())) {
        lcm_.publish(channel_, &s);
      }
      if (forged_) PublishForged(seq);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  // A straight line from the window's lower left to its lower right, tagged by `tagger`
  // with the session's epoch and a fresh sequence: only its tag is wrong.
  void PublishForgedShape(int64_t seq, const auth::Tagger& tagger) {
    thread_shape_t line = ArcShape(seq);
    for (int i = 0; i < kNodes; ++i) line.positions[i] = {-1.0 + 2.0 * i / (kNodes - 1), -0.5, 0.0};
    if (auth::Sign(&line, channel_, epoch_, auth_seq_.Next(), tagger)) {
      lcm_.publish(channel_, &line);
      forged_sent_++;
    }
  }
  void PublishForged(int64_t seq) {
    PublishForgedShape(seq, device_.tagger());
    PublishForgedShape(seq, other_server_.tagger());
  }

  void PublishGarbage(int64_t seq, std::mt19937* rng) {
    thread_shape_t s = ArcShape(seq);
    std::vector<uint8_t> buf(s.getEncodedSize());
    s.encode(buf.data(), 0, int(buf.size()));
    switch (seq % 5) {
      case 0: {  // random bytes
        std::vector<uint8_t> junk(100 + (*rng)() % 400);
        for (auto& b : junk) b = uint8_t((*rng)());
        lcm_.publish(channel_, junk.data(), junk.size());
        break;
      }
      case 1:  // truncated mid-positions
        lcm_.publish(channel_, buf.data(), buf.size() / 2);
        break;
      case 2: {  // num_nodes claims far more nodes than the buffer holds
        // fingerprint 8, utime 8, seq 8, scene (4 + 9), model (4 + 8), then num_nodes.
        const size_t at = 8 + 8 + 8 + 4 + s.scene.size() + 1 + 4 + s.model.size() + 1;
        const uint8_t huge[4] = {0x7f, 0xff, 0xff, 0xff};
        std::memcpy(&buf[at], huge, 4);
        lcm_.publish(channel_, buf.data(), buf.size());
        break;
      }
      case 3: {  // string length INT32_MIN
        const uint8_t neg[4] = {0x80, 0, 0, 0};
        std::memcpy(&buf[24], neg, 4);
        lcm_.publish(channel_, buf.data(), buf.size());
        break;
      }
      default: {  // a NaN node position: decodes, must be refused by validation
        thread_shape_t bad = ArcShape(seq);
        bad.positions[3][1] = std::nan("");
        lcm_.publish(channel_, &bad);
        break;
      }
    }
    garbage_sent_++;
  }

  const SessionKeyFile key_file_;
  const auth::KeySet server_ =
      auth::KeySet::FromRoot(auth::SessionKey::FromBytes(key_file_.key().data(), auth::SessionKey::kBytes));
  const auth::KeySet device_ = auth::KeySet::ForRole(key_file_.key(), auth::Role::kDevice, "hand");
  const auth::KeySet other_server_ = auth::KeySet::FromRoot(auth::SessionKey::Generate());
  const bool forged_;
  const int64_t epoch_ = auth::NewEpoch();
  auth::AuthSequence auth_seq_;
  lcm::LCM lcm_{kLoopbackUrl};
  std::string channel_;
  std::string status_channel_;
  bool garbage_;
  int8_t status_;
  std::function<void(thread_shape_t*)> decorate_;
  std::atomic<bool> running_{true};
  std::atomic<int64_t> garbage_sent_{0};
  std::atomic<int64_t> forged_sent_{0};
  std::thread thread_;
};

struct ViewerRun {
  ProcessResult result;
  std::string png;
};

// `key`: the --key given ("" = SNAPTHREAD_KEY_FILE's root key).
ViewerRun RunViewerScreenshot(const std::string& session, const std::string& dir,
                              int after_shapes, double timeout_s, const std::string& key = "") {
  ViewerRun run;
  run.png = dir + "/shot.png";
  const VirtualDisplay display(dir);
  EXPECT_TRUE(display.ready()) << "Xvfb did not start: " << display.error();
  if (!display.ready()) return run;
  std::vector<std::string> args = {
      BinDir() + "/snapthread-viewer", "--session", session, "--lcm-url", kLoopbackUrl,
      "--screenshot", run.png, "--after-shapes", std::to_string(after_shapes), "--timeout-s",
      std::to_string(timeout_s), "--width", std::to_string(kWidth), "--height",
      std::to_string(kHeight)};
  if (!key.empty()) args.insert(args.end(), {"--key", key});
  const std::vector<std::string> argv = display.On(args);
  ChildProcess viewer(argv, OutputFiles(dir + "/out.txt", dir + "/err.txt", true));
  EXPECT_TRUE(viewer.started()) << "cannot start snapthread-viewer";
  if (viewer.started()) run.result = viewer.Finish(timeout_s + 40.0);
  return run;
}

bool IsBackground(const uint8_t* p) {
  // Renderer's kBackground (0.11, 0.12, 0.15) in 8 bits, a few levels of tolerance.
  return std::abs(p[0] - 28) <= 4 && std::abs(p[1] - 31) <= 4 && std::abs(p[2] - 38) <= 4;
}

bool InOverlay(double x, double y, double margin) {
  const viewer::HudLayout l = viewer::MakeHudLayout(kWidth, kHeight);
  auto inside = [&](const viewer::PixelRect& r) {
    return x >= r.x - margin && x < r.x + r.width + margin && y >= r.y - margin &&
           y < r.y + r.height + margin;
  };
  return inside(l.text) || inside(l.chart);
}

// Checks the screenshot against the projection of the arc with the viewer's camera fit.
// The camera the viewer fits to the arc.
OrbitCamera ArcCamera() {
  const std::vector<Point3> nodes = ArcNodes();
  Eigen::Vector3d lo = nodes[0], hi = nodes[0];
  for (const auto& p : nodes) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  OrbitCamera camera;
  camera.Fit(lo, hi, double(kWidth) / kHeight);
  return camera;
}

// The arc's spline as `camera` projects it, in pixels.
std::vector<Eigen::Vector2d> ArcPixelPath(const OrbitCamera& camera) {
  std::vector<Eigen::Vector2d> path;
  for (const auto& p : CatmullRomCurve(ArcNodes(), 8)) path.push_back(camera.ProjectToPixel(p, kWidth, kHeight));
  return path;
}

void ExpectArcDrawn(const Image& img) {
  ASSERT_EQ(img.width, kWidth);
  ASSERT_EQ(img.height, kHeight);
  const OrbitCamera camera = ArcCamera();
  const std::vector<Eigen::Vector2d> path = ArcPixelPath(camera);
  // 1) Along the projected path the tube is drawn (not background).
  int on = 0, checked = 0;
  for (const auto& q : path) {
    if (InOverlay(q.x(), q.y(), 4)) continue;
    const int x = int(std::lround(q.x())), y = int(std::lround(q.y()));
    ASSERT_TRUE(x >= 0 && x < kWidth && y >= 0 && y < kHeight) << "arc projects off screen";
    checked++;
    on += !IsBackground(img.At(x, y));
  }
  ASSERT_GE(checked, 60) << "too few path samples outside the overlays";
  EXPECT_GE(on, int(0.95 * checked)) << on << " of " << checked << " path pixels drawn";
  // The path spans the window: the arc is 2 units wide, the fit fills ~70% of the height.
  double min_x = 1e9, max_x = -1e9;
  for (const auto& q : path) {
    min_x = std::min(min_x, q.x());
    max_x = std::max(max_x, q.x());
  }
  EXPECT_GT(max_x - min_x, 0.4 * kWidth);
  // 2) Far from the path (and outside the overlays) everything is background: this includes
  //    the inside of the arc, so a filled blob or a straight line would fail.
  int far = 0, far_background = 0;
  for (int y = 2; y < kHeight - 2; y += 6) {
    for (int x = 2; x < kWidth - 2; x += 6) {
      if (InOverlay(x, y, 2)) continue;
      double d = 1e9;
      for (const auto& q : path) d = std::min(d, std::hypot(q.x() - x, q.y() - y));
      if (d < 30) continue;
      far++;
      far_background += IsBackground(img.At(x, y));
    }
  }
  ASSERT_GT(far, 1000);
  EXPECT_GE(far_background, int(0.995 * far)) << far - far_background << " of " << far
                                               << " pixels far from the thread are not background";
  // 3) A point just inside the arc's apex is background, a point on the apex is not.
  const Eigen::Vector2d apex = camera.ProjectToPixel({0.0, 1.0, 0.0}, kWidth, kHeight);
  const Eigen::Vector2d centre = camera.ProjectToPixel({0.0, 0.5, 0.0}, kWidth, kHeight);
  EXPECT_FALSE(IsBackground(img.At(int(apex.x()), int(apex.y()))));
  EXPECT_TRUE(IsBackground(img.At(int(centre.x()), int(centre.y()))));
}

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

// Shapes MACed with a device key of the session, or signed by another session's server,
// arrive between the genuine ones: the viewer on an observer credential draws only the
// arc (a forged line drawn would show below it), and --print-rates counts the forged.
TEST(ViewerScreenshotTest, RefusesAndCountsShapesTheServerDidNotSign) {
  const std::string session = UniqueSession("VIEWFORGE");
  const std::string dir = FreshTempDir("viewer-forge");
  ShapePublisher publisher(session, /*with_garbage=*/false, 0, {}, /*with_forged=*/true);
  const std::string observer = WriteCredential(dir, publisher.root(), auth::Role::kObserver);
  ASSERT_TRUE(publisher.Start());
  const ViewerRun run = RunViewerScreenshot(session, dir, 20, 30.0, observer);
  ASSERT_TRUE(run.result.exited) << run.result.err;
  ASSERT_EQ(run.result.exit_code, 0) << run.result.out << run.result.err;
  Image img;
  std::string error;
  ASSERT_TRUE(ReadPng(run.png, &img, &error)) << error;
  ExpectArcDrawn(img);
  ChildProcess rates({BinDir() + "/snapthread-viewer", "--print-rates", "--session", session, "--lcm-url",
                      kLoopbackUrl, "--key", observer, "--duration-s", "3"},
                     OutputFiles(dir + "/rates_out.txt", dir + "/rates_err.txt", true));
  ASSERT_TRUE(rates.started());
  const ProcessResult r = rates.Finish(20.0);
  publisher.Stop();
  ASSERT_TRUE(r.exited && r.exit_code == 0) << r.out << r.err;
  const size_t at = r.out.find("REJECTED ");
  ASSERT_NE(at, std::string::npos) << r.out;
  // 3 s at 50 Hz, two forged shapes each time (loopback UDP may drop a few).
  EXPECT_GE(std::stoll(r.out.substr(at + 9)), 150) << r.out;
  EXPECT_NE(r.err.find("refused SHAPE"), std::string::npos) << r.err;
}

// A device's or an operator's credential is no observer's: the viewer refuses to start,
// naming the observer role.
TEST(ViewerScreenshotTest, RefusesAnotherRolesCredential) {
  const std::string dir = FreshTempDir("viewer-role");
  const auth::SessionKey root = auth::SessionKey::Generate();
  for (const auth::Role role : {auth::Role::kDevice, auth::Role::kOperator}) {
    const std::string cred = WriteCredential(dir, root, role, "hand");
    ChildProcess viewer({BinDir() + "/snapthread-viewer", "--print-rates", "--session", "VIEWROLE", "--lcm-url",
                         kLoopbackUrl, "--key", cred, "--duration-s", "1"},
                        OutputFiles(dir + "/out.txt", dir + "/err.txt", true));
    ASSERT_TRUE(viewer.started());
    const ProcessResult r = viewer.Finish(20.0);
    ASSERT_TRUE(r.exited) << r.err;
    EXPECT_NE(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.err.find("observer"), std::string::npos) << r.err;
  }
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

// Review path of docs/lab-setup.md: a logged session played back with lcm-logplayer into a
// viewer shows the logged thread.
TEST(ViewerScreenshotTest, ReplaysALoggedSessionWithLcmLogplayer) {
  const std::string session = UniqueSession("VIEWREPLAY");
  const std::string dir = FreshTempDir("viewer-replay");
  const std::string log_path = dir + "/session.lcmlog";
  const SessionKeyFile key_file;  // the logged session's root key
  const auth::KeySet server =
      auth::KeySet::FromRoot(auth::SessionKey::FromBytes(key_file.key().data(), auth::SessionKey::kBytes));
  // Reviewed with an observer credential of that session.
  const std::string observer = WriteCredential(dir, key_file.key(), auth::Role::kObserver);
  {
    lcm::LogFile log(log_path, "w");
    ASSERT_TRUE(log.good());
    const std::string channel = messages::Channels(session).shape;
    const int64_t epoch = auth::NewEpoch();
    auth::AuthSequence auth_seq;
    for (int k = 0; k < 400; ++k) {  // 8 s of shapes at 50 Hz, a signed status before each
      solver_status_t st{};
      st.seq = k;
      st.scene = "test-arc";
      st.method = "newton";
      ASSERT_TRUE(auth::Sign(&st, messages::Channels(session).solver_status, epoch,
                             auth_seq.Next(), server.tagger()));
      std::vector<uint8_t> status_buf(st.getEncodedSize());
      st.encode(status_buf.data(), 0, int(status_buf.size()));
      lcm::LogEvent se;
      se.timestamp = 1700000000000000 + k * 20000 - 1;
      se.channel = messages::Channels(session).solver_status;
      se.datalen = int32_t(status_buf.size());
      se.data = status_buf.data();
      ASSERT_EQ(log.writeEvent(&se), 0);
      thread_shape_t s = ArcShape(k);
      ASSERT_TRUE(auth::Sign(&s, channel, epoch, auth_seq.Next(), server.tagger()));
      std::vector<uint8_t> buf(s.getEncodedSize());
      s.encode(buf.data(), 0, int(buf.size()));
      lcm::LogEvent e;
      e.timestamp = 1700000000000000 + k * 20000;
      e.channel = channel;
      e.datalen = int32_t(buf.size());
      e.data = buf.data();
      ASSERT_EQ(log.writeEvent(&e), 0);
    }
  }
  // The viewer first (it must be listening: it says so once subscribed and its window is
  // up), then the player.
  const VirtualDisplay display(dir);
  ASSERT_TRUE(display.ready()) << "Xvfb did not start: " << display.error();
  const std::vector<std::string> viewer_argv = display.On({
      BinDir() + "/snapthread-viewer", "--session", session, "--lcm-url", kLoopbackUrl,
      "--screenshot", dir + "/shot.png", "--after-shapes", "10", "--timeout-s", "30",
      "--width", std::to_string(kWidth), "--height", std::to_string(kHeight), "--key", observer});
  ChildProcess viewer(viewer_argv, OutputFiles(dir + "/out.txt", dir + "/err.txt", true));
  ASSERT_TRUE(viewer.started());
  const bool listening = WaitUntil(
      [&] { return viewer.Err().find("listening on") != std::string::npos || !viewer.running(); }, 30.0);
  ASSERT_TRUE(listening && viewer.running()) << "viewer did not start listening:\n"
                                             << viewer.Out() << viewer.Err();
  ChildProcess player({"lcm-logplayer", std::string("--lcm-url=") + kLoopbackUrl, log_path},
                      OutputFiles(dir + "/player_out.txt", dir + "/player_err.txt", true));
  ASSERT_TRUE(player.started()) << "cannot start lcm-logplayer (liblcm-bin)";
  const ProcessResult v = viewer.Finish(60.0);
  // The player would go on to the end of the log; the viewer has what it needs.
  player.Finish(0.2);
  ASSERT_TRUE(v.exited) << v.err;
  ASSERT_EQ(v.exit_code, 0) << v.out << v.err;
  Image img;
  std::string error;
  ASSERT_TRUE(ReadPng(dir + "/shot.png", &img, &error)) << error;
  ExpectArcDrawn(img);
}

// Collects device_state_t from a session over udpm on its own thread.
class PoseCollector {
 public:
  explicit PoseCollector(const std::string& session) {
    messages::Subscribe<&PoseCollector::On>(lcm_, messages::Channels(session).device_state, this);
    thread_ = std::thread([this] {
      while (running_) lcm_.handleTimeout(20);
    });
  }
  ~PoseCollector() {
    running_ = false;
    thread_.join();
  }
  std::vector<device_state_t> Poses() {
    std::lock_guard<std::mutex> lock(mutex_);
    return poses_;
  }

 private:
  void On(const lcm::ReceiveBuffer*, const std::string&, const device_state_t* msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    poses_.push_back(*msg);
  }
  lcm::LCM lcm_{kLoopbackUrl};
  std::atomic<bool> running_{true};
  std::mutex mutex_;
  std::vector<device_state_t> poses_;
  std::thread thread_;
};

// --grasp-mode end to end: a real mouse drag (xdotool in the Xvfb display) from the grasp
// to another pixel makes the viewer publish device states at the dragged-to point, in
// device metres through the scene's mapping.
TEST(ViewerScreenshotTest, GraspModeDragPublishesDeviceStates) {
  const std::string session = UniqueSession("VIEWGRASP");
  const std::string dir = FreshTempDir("viewer-grasp");
  const std::string scene_path = SourceDir() + "/scenes/curve2d_snap.yaml";
  const Scene scene = LoadScene(scene_path);
  // Where the viewer's camera puts the arc's grasp (-1, 0, 0), and the drag target.
  const OrbitCamera camera = ArcCamera();
  const Eigen::Vector2d grasp_px = camera.ProjectToPixel(ArcNodes().back(), kWidth, kHeight);
  const Eigen::Vector2d target_px(std::round(grasp_px.x() + 60), std::round(grasp_px.y() - 45));
  Eigen::Vector3d origin, direction;
  camera.PixelRay(target_px.x(), target_px.y(), kWidth, kHeight, &origin, &direction);
  const Eigen::Vector3d target_model = origin - origin.z() / direction.z() * direction;  // z = 0
  const Eigen::Vector3d expected_m = messages::ModelPointToDevice(scene.device, target_model);

  ShapePublisher publisher(session, /*with_garbage=*/false);
  ASSERT_TRUE(publisher.Start());
  const std::string driven_name =
      scene.grasps.size() == 1 && !scene.grasps.front().name.empty() ? scene.grasps.front().name : "hand";
  const auth::KeySet driven = auth::KeySet::ForRole(publisher.root(), auth::Role::kDevice, driven_name);
  PoseCollector collector(session);
  const std::string viewer = BinDir() + "/snapthread-viewer";
  const std::string title = "snapthread-viewer: " + session;
  char script[2048];
  std::snprintf(script, sizeof script,
                "'%s' --grasp-mode --scene '%s' --session %s --lcm-url '%s' --width %d --height %d "
                "--duration-s 12 & vp=$!; "
                "for i in $(seq 50); do w=$(xdotool search --name '%s' | head -1); "
                "[ -n \"$w\" ] && break; sleep 0.2; done; sleep 1.5; "
                "xdotool mousemove --window $w %d %d; sleep 0.3; xdotool mousedown 1; sleep 0.3; "
                "xdotool mousemove --window $w %d %d; sleep 0.3; xdotool mousemove --window $w %d %d; "
                "sleep 1.0; xdotool mouseup 1; sleep 0.5; kill $vp; wait $vp; exit 0",
                viewer.c_str(), scene_path.c_str(), session.c_str(), kLoopbackUrl, kWidth, kHeight,
                title.c_str(), int(std::lround(grasp_px.x())), int(std::lround(grasp_px.y())),
                int(target_px.x() - 20), int(target_px.y()), int(target_px.x()), int(target_px.y()));
  const VirtualDisplay display(dir);
  ASSERT_TRUE(display.ready()) << "Xvfb did not start: " << display.error();
  ChildProcess run(display.On({"bash", "-c", script}), OutputFiles(dir + "/out.txt", dir + "/err.txt", true));
  ASSERT_TRUE(run.started());
  const ProcessResult r = run.Finish(40.0);
  publisher.Stop();
  ASSERT_TRUE(r.exited) << r.err;
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const std::vector<device_state_t> poses = collector.Poses();
  ASSERT_GE(poses.size(), 10u) << "viewer published " << poses.size() << " poses\n" << r.out << r.err;
  for (size_t i = 1; i < poses.size(); ++i) EXPECT_EQ(poses[i].seq, poses[i - 1].seq + 1);
  for (const auto& p : poses) {
    EXPECT_EQ(p.buttons, 1);  // published only while the button is held
    EXPECT_EQ(p.device_id, "viewer-mouse");
    // Tagged as the device of the scene's grasp (the root key's viewer acts as it), with
    // the epoch the viewer learned from the publisher's signed status.
    EXPECT_EQ(p.epoch, publisher.epoch());
    EXPECT_GT(p.auth_seq, 0);
    EXPECT_EQ(p.sender_role, static_cast<int8_t>(auth::Role::kDevice));
    EXPECT_EQ(p.sender_name, driven_name);
    device_state_t copy = p;
    std::vector<uint8_t> bytes(copy.getEncodedSize());
    copy.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    EXPECT_TRUE(auth::VerifyMac(bytes.data(), bytes.size(), messages::Channels(session).device_state,
                                *driven.mac_key()))
        << "the pose carries the MAC of the grasp's device key";
  }
  // The pose while held at the target: the model point under the cursor, in device metres
  // (one pixel is ~0.007 model units = 0.14 mm here).
  const device_state_t& last = poses.back();
  EXPECT_NEAR(last.position[0], expected_m.x(), 5e-4);
  EXPECT_NEAR(last.position[1], expected_m.y(), 5e-4);
  EXPECT_NEAR(last.position[2], expected_m.z(), 1e-9);  // planar model: on the plane z = 0
  // The drag moved it: far from the grasp's own position.
  const Eigen::Vector3d grasp_m = messages::ModelPointToDevice(scene.device, ArcNodes().back());
  EXPECT_GT(std::hypot(last.position[0] - grasp_m.x(), last.position[1] - grasp_m.y()), 5e-3);
}

TEST(ViewerScreenshotTest, TimesOutWithAClearMessageWhenNothingArrives) {
  const std::string session = UniqueSession("VIEWNONE");
  const std::string dir = FreshTempDir("viewer-none");
  const SessionKeyFile key_file;
  const ViewerRun run = RunViewerScreenshot(session, dir, 1, 1.5);
  ASSERT_TRUE(run.result.exited) << run.result.err;
  EXPECT_EQ(run.result.exit_code, 2);
  EXPECT_NE(run.result.err.find("timeout"), std::string::npos) << run.result.err;
  EXPECT_NE(run.result.err.find(session + "_SHAPE"), std::string::npos) << run.result.err;
}

}  // namespace
}  // namespace snapthread::viewer_test
