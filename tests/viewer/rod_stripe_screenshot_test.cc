// Issue 14 item 3 end to end: snapthread-viewer (a real process on its own Xvfb, real
// OpenGL) draws a rod shape's material frame as a dark stripe that winds with d1 and
// colours the tube by twist density. The rod is straight along +x (20 edges, length 1)
// with d1 turning uniformly about it; the test projects it with the viewer's camera and
// reads the stripe's position across the tube at edge midpoints from the PNG.
#include <atomic>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <thread>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "hud_layout.h"
#include "material_frames.h"
#include "messages/channels.h"
#include "orbit_camera.h"
#include "png_image.h"
#include "marker_colors.h"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"
#include "test_support.h"

namespace snapthread::viewer_test {
namespace {

using namespace test_support;
using viewer::OrbitCamera;
using V3 = Eigen::Vector3d;

// Large enough that the tube (radius 0.012 of the shape's extent) is ~16 px across.
constexpr int kWidth = 1100;
constexpr int kHeight = 1000;
constexpr const char* kScreen = "1280x1024x24";
constexpr int kEdges = 20;
constexpr double kLength = 1.0;
constexpr double kEll = kLength / kEdges;

// d1 of edge j of the rod whose twist density is `tau` (rad per unit length): turned by
// tau ℓ per edge about +x from +y (right-handed for tau > 0).
V3 Director(int j, double tau) {
  const double a = tau * kEll * j;
  return V3(0.0, std::cos(a), std::sin(a));
}

thread_shape_t RodShape(int64_t seq, double tau) {
  thread_shape_t s{};
  s.utime = seq * 16000;
  s.seq = seq;
  s.scene = "test-rod";
  s.model = "rod";
  s.num_nodes = kEdges + 1;
  for (int k = 0; k <= kEdges; ++k) s.positions.push_back({k * kEll, 0.0, 0.0});
  s.num_frames = kEdges;
  for (int j = 0; j < kEdges; ++j) {
    const V3 d = Director(j, tau);
    s.frames.push_back({d.x(), d.y(), d.z(), tau});
  }
  for (int i = 0; i < 3; ++i) {
    s.grasp[i] = s.positions.back()[i];
    s.grip_direction[i] = 0.0;  // no arrows: only the tube, the clamp and the grasp
    s.force[i] = 0.0;
    s.force_newtons[i] = 0.0;
  }
  return s;
}

// Publishes the rod (and a signed status before each shape, as the server does) every
// 20 ms until destroyed.
class RodPublisher {
 public:
  RodPublisher(const std::string& session, double tau)
      : channels_(session), tau_(tau), thread_([this] { Loop(); }) {}
  ~RodPublisher() {
    running_ = false;
    thread_.join();
  }

 private:
  void Loop() {
    int64_t seq = 0;
    while (running_) {
      solver_status_t st{};
      st.seq = seq;
      st.scene = "test-rod";
      st.method = "newton";
      if (auth::Sign(&st, channels_.solver_status, epoch_, auth_seq_.Next(), server_.tagger())) {
        lcm_.publish(channels_.solver_status, &st);
      }
      thread_shape_t s = RodShape(++seq, tau_);
      if (auth::Sign(&s, channels_.shape, epoch_, auth_seq_.Next(), server_.tagger())) {
        lcm_.publish(channels_.shape, &s);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  const SessionKeyFile key_file_;
  // Signs as the server would (the viewer, on the root key, verifies its derived key).
  const auth::KeySet server_ =
      auth::KeySet::FromRoot(auth::SessionKey::FromBytes(key_file_.key().data(), auth::SessionKey::kBytes));
  const int64_t epoch_ = auth::NewEpoch();
  auth::AuthSequence auth_seq_;
  lcm::LCM lcm_{kLoopbackLcmUrl};
  const messages::Channels channels_;
  const double tau_;
  std::atomic<bool> running_{true};
  std::thread thread_;
};

// The viewer's screenshot of the rod with twist density `tau`.
Image Screenshot(double tau, const std::string& name) {
  const std::string session = UniqueSession("VIEWROD");
  const std::string dir = FreshTempDir("viewer-rod-" + name);
  RodPublisher publisher(session, tau);
  const VirtualDisplay display(dir, kScreen);
  EXPECT_TRUE(display.ready()) << "Xvfb did not start: " << display.error();
  if (!display.ready()) return {};
  const std::string png = dir + "/shot.png";
  ChildProcess viewer(display.On({BinDir() + "/snapthread-viewer", "--session", session,
                                  "--lcm-url", kLoopbackLcmUrl, "--screenshot", png,
                                  "--after-shapes", "3", "--timeout-s", "30", "--width",
                                  std::to_string(kWidth), "--height", std::to_string(kHeight)}),
                      OutputFiles(dir + "/out.txt", dir + "/err.txt", true));
  EXPECT_TRUE(viewer.started());
  if (!viewer.started()) return {};
  const ProcessResult r = viewer.Finish(70.0);
  EXPECT_TRUE(r.exited && r.exit_code == 0) << r.out << r.err;
  Image img;
  std::string error;
  EXPECT_TRUE(ReadPng(png, &img, &error)) << error;
  return img;
}

// The camera the viewer sets for a 3-D model's first shape (viewer_app.cc): the oblique
// start view, fitted to the nodes.
OrbitCamera RodCamera() {
  OrbitCamera camera;
  camera.SetAngles(0.5, 0.35);
  camera.Fit(V3::Zero(), V3(kLength, 0.0, 0.0), double(kWidth) / kHeight);
  return camera;
}

bool IsBackground(const uint8_t* p) {
  return std::abs(p[0] - 28) <= 4 && std::abs(p[1] - 31) <= 4 && std::abs(p[2] - 38) <= 4;
}
// The stripe: kStripeColor (0.06) lit by at most 1.0, i.e. <= 16 levels in every channel.
// The tube's darkest shade (lit 0.35) has a channel >= 30 and the background's is 38.
bool IsStripe(const uint8_t* p) { return p[0] <= 22 && p[1] <= 22 && p[2] <= 22; }

// One cross-section of the tube in the screenshot: a scan across the projected axis.
struct Section {
  V3 centre;             // on the axis (world)
  double facing = 0.0;   // d1 · (unit vector to the eye): 1 = stripe faces the camera
  double predicted = 0;  // stripe centre's offset across the tube, pixels
  double tube_lo = 0, tube_hi = 0;  // the tube's extent along the scan (pixels from centre)
  int tube_pixels = 0;
  int stripe_pixels = 0;
  double stripe_offset = 0.0;  // mean offset of the stripe pixels
  Eigen::Vector3d mean_colour = Eigen::Vector3d::Zero();  // of the tube's non-stripe pixels
};

Section Measure(const Image& img, const OrbitCamera& camera, int edge, double tau) {
  Section s;
  s.centre = V3((edge + 0.5) * kEll, 0.0, 0.0);
  const double radius = 0.012 * kLength;  // renderer: 0.012 of the nodes' extent
  const Eigen::Vector2d c = camera.ProjectToPixel(s.centre, kWidth, kHeight);
  const Eigen::Vector2d along =
      (camera.ProjectToPixel(s.centre + V3(0.01, 0, 0), kWidth, kHeight) - c).normalized();
  const Eigen::Vector2d across(-along.y(), along.x());
  const V3 d1 = Director(edge, tau);
  s.facing = d1.dot((camera.Eye() - s.centre).normalized());
  s.predicted = (camera.ProjectToPixel(s.centre + radius * d1, kWidth, kHeight) - c).dot(across);
  double stripe_sum = 0.0;
  s.tube_lo = 1e9;
  s.tube_hi = -1e9;
  for (double t = -25.0; t <= 25.0; t += 0.5) {
    const Eigen::Vector2d q = c + t * across;
    const uint8_t* p = img.At(int(std::lround(q.x())), int(std::lround(q.y())));
    if (IsBackground(p)) continue;
    s.tube_lo = std::min(s.tube_lo, t);
    s.tube_hi = std::max(s.tube_hi, t);
    s.tube_pixels++;
    if (IsStripe(p)) {
      s.stripe_pixels++;
      stripe_sum += t;
    } else {
      s.mean_colour += Eigen::Vector3d(p[0], p[1], p[2]);
    }
  }
  if (s.stripe_pixels > 0) s.stripe_offset = stripe_sum / s.stripe_pixels;
  if (s.tube_pixels > s.stripe_pixels) s.mean_colour /= (s.tube_pixels - s.stripe_pixels);
  return s;
}

// Edges whose midpoints are away from the clamp and grasp markers and the overlays.
std::vector<int> Stations(const OrbitCamera& camera) {
  const viewer::HudLayout l = viewer::MakeHudLayout(kWidth, kHeight);
  std::vector<int> edges;
  for (int j = 3; j <= kEdges - 4; ++j) {
    const Eigen::Vector2d q = camera.ProjectToPixel(V3((j + 0.5) * kEll, 0, 0), kWidth, kHeight);
    bool clear = true;
    for (const viewer::PixelRect& r : {l.text, l.chart, l.legend}) {
      clear = clear && !(q.x() > r.x - 40 && q.x() < r.x + r.width + 40 && q.y() > r.y - 40 &&
                         q.y() < r.y + r.height + 40);
    }
    if (clear) edges.push_back(j);
  }
  return edges;
}

// Two turns of d1 over the rod: the stripe shows where d1 faces the camera, at the side
// of the tube d1 points to, and is hidden where d1 faces away.
TEST(RodStripeScreenshotTest, StripeWindsWithTheMaterialDirector) {
  const double tau = 2.0 * 2.0 * std::numbers::pi / ((kEdges - 1) * kEll);  // 2 turns
  const Image img = Screenshot(tau, "stripe");
  ASSERT_EQ(img.width, kWidth);
  ASSERT_EQ(img.height, kHeight);
  const OrbitCamera camera = RodCamera();
  const std::vector<int> stations = Stations(camera);
  ASSERT_GE(stations.size(), 10u);
  int facing = 0, away = 0, left = 0, right = 0;
  double worst = 0.0;  // largest |stripe offset - d1's projection| where the stripe is seen
  for (int j : stations) {
    const Section s = Measure(img, camera, j, tau);
    // The tube is there, as wide as the renderer's radius predicts (~8 px each side).
    ASSERT_GE(s.tube_pixels, 16) << "edge " << j << ": no tube drawn across the axis";
    const double half_width = 0.5 * (s.tube_hi - s.tube_lo);
    EXPECT_GT(half_width, 4.0) << "edge " << j;
    EXPECT_LT(half_width, 14.0) << "edge " << j;
    if (s.facing > 0.5) {  // d1 within 60° of the view direction: the stripe is seen
      facing++;
      EXPECT_GE(s.stripe_pixels, 3) << "edge " << j << ": stripe missing, facing " << s.facing;
      EXPECT_NEAR(s.stripe_offset, s.predicted, std::max(2.5, 0.3 * half_width))
          << "edge " << j << ": stripe at " << s.stripe_offset << " px, d1 projects to "
          << s.predicted << " px (tube " << s.tube_lo << " .. " << s.tube_hi << ")";
      if (s.stripe_pixels > 0) worst = std::max(worst, std::abs(s.stripe_offset - s.predicted));
      if (s.stripe_pixels >= 3 && s.stripe_offset < -0.3 * half_width) left++;
      if (s.stripe_pixels >= 3 && s.stripe_offset > 0.3 * half_width) right++;
    } else if (s.facing < -0.45) {  // the whole ±22.5° band is on the far side
      away++;
      EXPECT_EQ(s.stripe_pixels, 0) << "edge " << j << ": stripe shown, but d1 faces away ("
                                    << s.facing << ")";
    }
  }
  std::printf("%zu stations: %d facing (worst offset error %.2f px), %d away, %d left, %d right\n",
              stations.size(), facing, worst, away, left, right);
  // Two turns over the stations: the stripe is seen and hidden repeatedly, on both sides.
  EXPECT_GE(facing, 3);
  EXPECT_GE(away, 3);
  EXPECT_GE(left, 1) << "the stripe never appears on one side of the tube";
  EXPECT_GE(right, 1) << "the stripe never appears on the other side of the tube";
}

// The angle between two colours as RGB directions: lighting scales a colour, so the
// direction of a lit surface's colour is its material's (the hue the map chose).
double ColourAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0));
}

Eigen::Vector3d TubeColour(const Image& img, double tau) {
  const OrbitCamera camera = RodCamera();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (int j : Stations(camera)) {
    const Section s = Measure(img, camera, j, tau);
    if (s.tube_pixels - s.stripe_pixels < 5) continue;
    sum += s.mean_colour;
    n++;
  }
  EXPECT_GE(n, 8);
  return n > 0 ? Eigen::Vector3d(sum / n) : sum;
}

// Twist colour (material_frames.h): the untwisted rod is the state colour (pale blue),
// twice the full scale (one turn per length, 2π/L) is the saturated right-handed green,
// half the full scale left-handed is halfway to violet.
TEST(RodStripeScreenshotTest, TubeColourFollowsTheTwistMap) {
  const Eigen::Vector3f base = viewer::StatusColor(0);
  const double full = 2.0 * std::numbers::pi / kLength;
  struct Case {
    const char* name;
    double tau;
  } cases[] = {{"untwisted", 0.0}, {"right", 2.0 * full}, {"left-half", -0.5 * full}};
  Eigen::Vector3d measured[3];
  for (int i = 0; i < 3; ++i) {
    const Image img = Screenshot(cases[i].tau, cases[i].name);
    ASSERT_EQ(img.width, kWidth) << cases[i].name;
    measured[i] = TubeColour(img, cases[i].tau);
    const Eigen::Vector3d want = viewer::TwistColor(base, cases[i].tau, full).cast<double>();
    std::printf("%s: tube mean %.0f %.0f %.0f, %.2f deg from the map's hue\n", cases[i].name,
                measured[i].x(), measured[i].y(), measured[i].z(),
                ColourAngle(measured[i], want) * 180 / std::numbers::pi);
    // 8-bit rounding of a shade >= 0.35 moves the direction by well under 3°.
    EXPECT_LT(ColourAngle(measured[i], want), 3.0 * std::numbers::pi / 180)
        << cases[i].name << ": tube " << measured[i].transpose() << ", map says "
        << (255 * want).transpose() << " times the shade";
  }
  // The three are told apart: blue, green, violet.
  EXPECT_GT(measured[0].z(), measured[0].x() + 40) << measured[0].transpose();
  EXPECT_GT(measured[1].y(), measured[1].z() + 40) << measured[1].transpose();
  EXPECT_GT(measured[1].y(), measured[1].x() + 40) << measured[1].transpose();
  EXPECT_GT(measured[2].z(), measured[2].y() + 40) << measured[2].transpose();
  EXPECT_GT(ColourAngle(measured[0], measured[1]), 15.0 * std::numbers::pi / 180);
  EXPECT_GT(ColourAngle(measured[0], measured[2]), 5.0 * std::numbers::pi / 180);
}

}  // namespace
}  // namespace snapthread::viewer_test
