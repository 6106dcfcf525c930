#include "arc_session.h"

#include <algorithm>

#include "auth/credential.h"
#include "auth/credential_file.h"
#include "hud_layout.h"

namespace snapthread::viewer_test {

using namespace test_support;  // the shared fixtures (tests/support)

using viewer::CatmullRomCurve;
using viewer::OrbitCamera;
using viewer::Point3;

// A half circle of radius 1 from (1, 0) over (0, 1) to (-1, 0), in the z = 0 plane.
std::vector<Point3> ArcNodes() {
  std::vector<Point3> nodes;
  for (int i = 0; i < kNodes; ++i) {
    const double a = M_PI * i / (kNodes - 1);
    nodes.emplace_back(std::cos(a), std::sin(a), 0.0);
  }
  return nodes;
}

thread_shape_t ArcShape(int64_t seq, int8_t status) {
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
                            const std::string& name) {
  const std::string path = dir + "/" + std::string(auth::RoleToString(role)) + ".cred";
  auth::WriteCredentialFile(path, auth::IssueCredential(root, role, name, auth::kNeverExpires), true);
  return path;
}

// `key`: the --key given ("" = SNAPTHREAD_KEY_FILE's root key).
ViewerRun RunViewerScreenshot(const std::string& session, const std::string& dir,
                              int after_shapes, double timeout_s, const std::string& key) {
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

}  // namespace snapthread::viewer_test
