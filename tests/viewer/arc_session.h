// The screenshot tests' live session: a half circle published as the server would
// (ShapePublisher, with malformed or forged shapes when asked), snapthread-viewer run on it
// under Xvfb (RunViewerScreenshot), and the check that a screenshot shows the arc where the
// viewer's camera projects it (ExpectArcDrawn). Shared by viewer_screenshot_test and
// viewer_observer_test.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Core>
#include <lcm/lcm-cpp.hpp>

#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/role.h"
#include "auth/session_epoch.h"
#include "auth/session_key.h"
#include "messages/channels.h"
#include "orbit_camera.h"
#include "png_image.h"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"
#include "spline.h"
#include "test_support.h"

namespace snapthread::viewer_test {

inline constexpr const char* kLoopbackUrl = test_support::kLoopbackLcmUrl;
inline constexpr int kWidth = 640;
inline constexpr int kHeight = 480;
inline constexpr int kNodes = 21;

// A half circle of radius 1 from (1, 0) over (0, 1) to (-1, 0), in the z = 0 plane.
std::vector<viewer::Point3> ArcNodes();
// The arc as the server's shape `seq` with solver status `status`.
thread_shape_t ArcShape(int64_t seq, int8_t status = 0);
// A credential of `role` issued from `root`, written to `dir`; its path.
std::string WriteCredential(const std::string& dir, const auth::SessionKey& root, auth::Role role,
                            const std::string& name = "");

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

  const test_support::SessionKeyFile key_file_;
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
  test_support::ProcessResult result;
  std::string png;
};

// snapthread-viewer --screenshot on its own Xvfb after `after_shapes` shapes of `session`;
// `key`: the --key given ("" = SNAPTHREAD_KEY_FILE's root key).
ViewerRun RunViewerScreenshot(const std::string& session, const std::string& dir,
                              int after_shapes, double timeout_s, const std::string& key = "");
// Whether a pixel is the renderer's background.
bool IsBackground(const uint8_t* p);
// Whether a pixel is within `margin` of the overlays (text, chart).
bool InOverlay(double x, double y, double margin);
// The camera the viewer fits to the arc.
viewer::OrbitCamera ArcCamera();
// The arc's spline as `camera` projects it, in pixels.
std::vector<Eigen::Vector2d> ArcPixelPath(const viewer::OrbitCamera& camera);
// Checks the screenshot against the projection of the arc with the viewer's camera fit.
void ExpectArcDrawn(const Image& img);

}  // namespace snapthread::viewer_test
