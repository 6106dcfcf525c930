// Issue 25's "Done when" on real processes over udpm on loopback: the session runs from
// role credentials (the server on the root key, the device on its credential "hand", the
// viewer on an observer credential, snapthread-ctl on an operator's); the device gets
// force models with no fade, the viewer and the web bridge show the live thread, an operator loads a scene
// and an observer cannot.
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "role_session.h"
#include "web_feed.h"
#include "test_support.h"

namespace snapthread::roles_test {
namespace {

using test_support::ChildProcess;
using test_support::ProcessResult;

class RolesSessionTest : public RoleSessionTest {};

TEST_F(RolesSessionTest, SessionRunsFromRoleCredentials) {
  const std::string device_key = creds_->Issue(auth::Role::kDevice, "hand");
  const std::string observer_key = creds_->Issue(auth::Role::kObserver);
  const std::string operator_key = creds_->Issue(auth::Role::kOperator, "console");
  ASSERT_NO_FATAL_FAILURE(StartWatch());
  auto server = StartServer(creds_->root_path());
  auto device = StartDevice(device_key, "hand");
  // The viewer on the observer credential: it exits 0 once it has drawn the 5th verified
  // shape into its screenshot.
  const test_support::VirtualDisplay display(dir());
  ASSERT_TRUE(display.ready()) << display.error();
  const std::string png = dir() + "/viewer.png";
  ChildProcess viewer(display.On({bin_ + "/snapthread-viewer", "--key", observer_key, "--session", session_,
                                  "--lcm-url", test_support::kLoopbackLcmUrl, "--screenshot", png,
                                  "--after-shapes", "5", "--timeout-s", "60"}),
                      test_support::OneLog(dir() + "/viewer.log", true));
  ASSERT_TRUE(viewer.started());
#ifdef SNAPTHREAD_ROLES_TEST_WEB
  // The web bridge on the observer credential, read as its page reads it.
  WebFeed web(bin_, observer_key, session_, dir());
  ASSERT_TRUE(web.ok()) << web.error();
#endif

  ASSERT_TRUE(WaitForModels("hand", 30)) << device->Out() << server->Out();
  // Steady state: models keep arriving, no fade, nothing refused (the device's poses
  // before it learnt the session's epoch may have been).
  const auto before = watch_->NextDevice("hand", 10);
  const auto status_before = watch_->NextStatus(10);
  ASSERT_TRUE(before && status_before);
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const auto after = watch_->NextDevice("hand", 10);
  const auto status = watch_->NextStatus(10);
  ASSERT_TRUE(after && status);
  EXPECT_GT(after->models_received, before->models_received + 20) << device->Out();
  EXPECT_EQ(after->fades, before->fades) << "the device faded in steady state\n" << device->Out();
  EXPECT_EQ(after->models_rejected, before->models_rejected) << device->Out();
  EXPECT_EQ(status->scene, "curve2d_snap");
  EXPECT_GT(status->updates, status_before->updates);
  EXPECT_EQ(TotalRefusals(status->refusals), TotalRefusals(status_before->refusals)) << status->refusals;

  // The observer's console changes nothing.
  ProcessResult r = Ctl(observer_key, {"--timeout-s", "5", "load-scene", "zeeman"});
  EXPECT_NE(r.exit_code, 0) << r.out << r.err;
  // Refused at its start (an operator credential needed) or by the server.
  EXPECT_TRUE(ContainsWord(r.out + r.err, "operator")) << r.out << r.err;
  const auto kept = watch_->NextStatus(10);
  ASSERT_TRUE(kept);
  EXPECT_EQ(kept->scene, "curve2d_snap");
  // The operator's loads the scene.
  r = Ctl(operator_key, {"--timeout-s", "30", "load-scene", "zeeman"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(test_support::WaitUntil(
      [&] {
        const auto s = watch_->status();
        return s && s->scene == "zeeman";
      },
      15))
      << (watch_->status() ? watch_->status()->scene : "no status");
#ifdef SNAPTHREAD_ROLES_TEST_WEB
  // The page shows the live thread, the new scene's too.
  EXPECT_TRUE(test_support::WaitUntil([&] { return web.last_scene() == "zeeman"; }, 15))
      << web.shapes() << " shapes, the last of scene " << web.last_scene() << "\n" << web.process().Err();
  EXPECT_GT(web.shapes(), 5);
#endif
  r = Ctl(operator_key, {"--timeout-s", "30", "status"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("scene: zeeman"), std::string::npos) << r.out;

  int code = -1;
  EXPECT_TRUE(viewer.Wait(90, &code)) << viewer.Out();
  EXPECT_EQ(code, 0) << viewer.Out();
  EXPECT_TRUE(std::filesystem::exists(png)) << viewer.Out();
  // Every shape and status the observer saw verified; the device's statuses too.
  EXPECT_GT(watch_->shapes().verified, 5);
  EXPECT_EQ(watch_->shapes().refused, 0);
  EXPECT_EQ(watch_->statuses().refused, 0);
  EXPECT_GT(watch_->device_statuses().verified, 2);
  EXPECT_EQ(watch_->device_statuses().refused, 0);
#ifdef SNAPTHREAD_ROLES_TEST_WEB
  EXPECT_TRUE(test_support::TerminateTogether({server.get(), device.get(), &web.process()}, 10.0));
#else
  EXPECT_TRUE(test_support::TerminateTogether({server.get(), device.get()}, 10.0));
#endif
}

}  // namespace
}  // namespace snapthread::roles_test
