// Issue 25 item 4, revocation on a running session: `snapthread-keygen --revoke hand` and
// SIGHUP to the server. From the device's next pose on the server refuses it
// (device/revoked), answers no more, and the device, getting no model, fades to zero
// force: it accepts no model after the refusals start and its trace ends at zero force.
#include <signal.h>

#include <chrono>
#include <algorithm>
#include <cmath>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "role_session.h"
#include "test_support.h"

namespace snapthread::roles_test {
namespace {

using namespace std::chrono_literals;

class RevocationTest : public RoleSessionTest {};

TEST_F(RevocationTest, RevokedDeviceIsRefusedFromItsNextPose) {
  const std::string device_key = creds_->Issue(auth::Role::kDevice, "hand");
  ASSERT_NO_FATAL_FAILURE(StartWatch());
  auto server = StartServer(creds_->root_path());
  auto device = StartDevice(device_key, "hand", {"--model-timeout-ms", "200", "--fade-ms", "100"});
  ASSERT_TRUE(WaitForModels("hand", 30)) << device->Out() << server->Out();
  const auto live = watch_->NextDevice("hand", 10);
  ASSERT_TRUE(live);
  const auto live_status = watch_->NextStatus(10);
  ASSERT_TRUE(live_status);
  EXPECT_EQ(Refusals(live_status->refusals, "device/revoked"), 0) << live_status->refusals;

  const test_support::ProcessResult revoked = Keygen({"--revoke", "hand"});
  ASSERT_EQ(revoked.exit_code, 0) << revoked.out << revoked.err;
  server->Signal(SIGHUP);
  ASSERT_TRUE(test_support::WaitUntil(
      [&] {
        const auto s = watch_->status();
        return s && Refusals(s->refusals, "device/revoked") > 0;
      },
      15, 0.02))
      << (watch_->status() ? watch_->status()->refusals : "no status") << "\n" << server->Out();
  // What was in flight at the refusal has arrived by now.
  std::this_thread::sleep_for(300ms);
  const auto s0 = watch_->NextStatus(10);
  const auto d0 = watch_->NextDevice("hand", 10);
  ASSERT_TRUE(s0 && d0);
  std::this_thread::sleep_for(2s);
  const auto s1 = watch_->NextStatus(10);
  const auto d1 = watch_->NextDevice("hand", 10);
  ASSERT_TRUE(s1 && d1);
  ASSERT_TRUE(server->running() && device->running()) << server->Out() << device->Out();
  // Every pose refused (1 kHz for 2 s; generous for a loaded machine), none solved.
  EXPECT_GT(Refusals(s1->refusals, "device/revoked") - Refusals(s0->refusals, "device/revoked"), 200)
      << s1->refusals;
  EXPECT_EQ(s1->updates, s0->updates) << "the server solved a revoked device's pose";
  EXPECT_GT(d0->models_received, live->models_received - 1);
  EXPECT_EQ(d1->models_received, d0->models_received) << "a model accepted after the revocation";
  EXPECT_EQ(d1->force_norm_n, 0.0) << "the revoked device still renders a force";

  EXPECT_TRUE(test_support::TerminateTogether({server.get(), device.get()}, 10.0));
  const std::vector<test_support::DeviceTraceRow> trace = test_support::ReadDeviceTrace(trace_path("hand"));
  ASSERT_GT(trace.size(), 3000u);
  // It had a force once, and in its last second a zero force on a model older than 1 s.
  double max_force = 0.0;
  for (const auto& row : trace) max_force = std::max(max_force, row.force_n.norm());
  EXPECT_GT(max_force, 0.0);
  int with_force = 0, fresh_model = 0;
  for (size_t i = trace.size() - 1000; i < trace.size(); ++i) {
    with_force += trace[i].force_n.norm() != 0.0;
    fresh_model += trace[i].model_age_ms <= 1000.0;
  }
  EXPECT_EQ(with_force, 0) << "ticks of the last second with a force";
  EXPECT_EQ(fresh_model, 0) << "ticks of the last second on a model younger than 1 s";
}

}  // namespace
}  // namespace snapthread::roles_test
