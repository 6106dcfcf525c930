// End-to-end: snapthread-viewer on an observer credential (docs/security.md, "Roles on the
// wire"): it shows what the session's server signed, live and from a log, refuses and
// counts shapes it did not sign, refuses another role's credential, and in grasp mode
// drives as a device.
#include <atomic>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "arc_session.h"
#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "messages/channels.h"
#include "messages/pose_mapping.h"
#include "messages/subscribe.h"
#include "scene/scene.h"
#include "snapthread/device_state_t.hpp"

namespace snapthread::viewer_test {
namespace {

using namespace test_support;  // ChildProcess, VirtualDisplay, UniqueSession, ...
using viewer::OrbitCamera;

// Shapes MACed with a device key of the session, or signed by another session's server,
// arrive between the genuine ones: the viewer on an observer credential draws only the
// arc (a forged line drawn would show below it), and --print-rates counts the forged.
TEST(ViewerObserverTest, RefusesAndCountsShapesTheServerDidNotSign) {
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
TEST(ViewerObserverTest, RefusesAnotherRolesCredential) {
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
// Review path of docs/lab-setup.md: a logged session played back with lcm-logplayer into a
// viewer shows the logged thread.
TEST(ViewerObserverTest, ReplaysALoggedSessionWithLcmLogplayer) {
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
TEST(ViewerObserverTest, GraspModeDragPublishesDeviceStates) {
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
}  // namespace
}  // namespace snapthread::viewer_test
