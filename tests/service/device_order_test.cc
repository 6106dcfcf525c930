// Issue 12 item 4: under 20 % loss and 5 ± 2 ms delay (which reorders), the device
// applies force models in order and a snap is felt as ONE force step. A DeviceClient runs
// on a fake clock through an in-process lossy, reordering link (lossy_transport.h) to a
// server fake, along a path through a snap; the force handed to the device backend each
// tick is compared with the same run over a perfect link. Before ModelOrder, a model
// overtaken by a newer one was still rendered: across the snap the hand felt the new
// branch, the old one again, then the new one (three steps) in most unsigned runs.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "auth/session_epoch.h"
#include "auth/session_key.h"
#include "device_client.h"
#include "device_fakes.h"
#include "lossy_transport.h"
#include "messages/pose_mapping.h"
#include "model_order.h"
#include "scene/scene.h"
#include "server_messages.h"
#include "sim_path_device.h"
#include "stability.h"
#include "tracking/make_tracker.h"

namespace snapthread::device {
namespace {

using testing::InMemoryTransport;
using testing::LinkOptions;
using testing::LossyTransport;
using testing::SpringServer;

int64_t g_now_us = 0;
int64_t FakeClock() { return g_now_us; }

// ---- ModelOrder on its own --------------------------------------------------------------

TEST(DeviceModelOrderTest, OnlyNewerPosesAndSolvesPass) {
  for (bool check_solve_seq : {false, true}) {
    ModelOrder order(check_solve_seq);
    EXPECT_TRUE(order.IsNewer(7, 10, 100));  // the first one
    order.Applied(7, 10, 100);
    EXPECT_TRUE(order.IsNewer(7, 11, 101));
    EXPECT_FALSE(order.IsNewer(7, 11, 100));  // the same pose again (a duplicate)
    EXPECT_FALSE(order.IsNewer(7, 12, 99));   // a late pose answered after a newer one
    // A newer pose from an older solve: refused by seq when unsigned; signed sessions
    // leave the solve order to auth_seq (auth_seq orders the solves when signed).
    EXPECT_EQ(order.IsNewer(7, 9, 105), !check_solve_seq);
    EXPECT_EQ(order.IsNewer(7, 10, 105), !check_solve_seq);
    // Another server session numbers its solves afresh; the pose order still holds.
    EXPECT_TRUE(order.IsNewer(8, 1, 105));
    EXPECT_FALSE(order.IsNewer(8, 1, 100));
  }
}

// ---- the link itself ----------------------------------------------------------------------

TEST(DeviceLossyTransportTest, LosesDelaysAndReordersAsConfigured) {
  LinkOptions options;  // 20 %, 5 ± 2 ms
  testing::DelayLine<int> line(options, 42);
  const int kSent = 20000;
  std::vector<int64_t> sent_at(kSent);
  int delivered = 0;
  int64_t min_delay = INT64_MAX, max_delay = 0;
  for (int i = 0; i < kSent + 10; ++i) {
    const int64_t now = 1000 * static_cast<int64_t>(i);
    if (i < kSent) {
      sent_at[i] = now;
      line.Send(i, now);
    }
    line.DeliverDue(now, [&](int k) {
      min_delay = std::min(min_delay, now - sent_at[k]);
      max_delay = std::max(max_delay, now - sent_at[k]);
      ++delivered;
    });
  }
  EXPECT_NEAR(static_cast<double>(line.lost()) / kSent, 0.2, 0.015);
  EXPECT_EQ(delivered + static_cast<int>(line.lost()), kSent);
  EXPECT_GE(min_delay, 3000);  // polled each ms: a 3.0-7.0 ms delay is seen as 3-7 ms
  EXPECT_LE(max_delay, 7000);
  EXPECT_GT(line.reordered(), static_cast<uint64_t>(kSent / 10));
}

// ---- a spring with one snap -------------------------------------------------------------

// What one run rendered: the force handed to the backend each tick, and the counters.
struct Rendered {
  std::vector<double> fx_n;
  uint64_t received = 0, out_of_order = 0, auth_rejected = 0, snaps_felt = 0;
  uint64_t models_reordered = 0, models_lost = 0, poses_reordered = 0;
};

// Ticks where |dF| exceeds this are part of a force step; the path itself changes the
// spring force by 0.002 N per tick, a snap by 1.5 N (1 N per tick after the slew limit).
constexpr double kStepN = 0.1;
constexpr int kSettledTick = 200;  // the first model has faded in by then (100 ms ramp)
constexpr int kLegs = 8;           // 1 s each, one snap in each
constexpr int kTicks = kLegs * 1000 - 50;

// The first tick of each force step: runs of consecutive ticks with |dF| > kStepN.
std::vector<size_t> Steps(const std::vector<double>& fx) {
  std::vector<size_t> starts;
  bool in_step = false;
  for (size_t i = kSettledTick + 1; i < fx.size(); ++i) {
    const bool big = std::abs(fx[i] - fx[i - 1]) > kStepN;
    if (big && !in_step) starts.push_back(i);
    in_step = big;
  }
  return starts;
}

// Sign changes of dF from tick to tick (dF below round-off ignored).
int CountSignChanges(const std::vector<double>& fx) {
  int changes = 0, last = 0;
  for (size_t i = kSettledTick + 1; i < fx.size(); ++i) {
    const double d = fx[i] - fx[i - 1];
    const int sign = d > 1e-9 ? 1 : (d < -1e-9 ? -1 : 0);
    if (sign != 0 && last != 0 && sign != last) ++changes;
    if (sign != 0) last = sign;
  }
  return changes;
}

// Drives a DeviceClient back and forth along x between -2 cm and +2 cm at 4 cm/s against
// a 50 N/m spring that snaps (+1.5 N along x) at x = +5 mm and back at x = -5 mm, over a
// perfect link (link == nullptr) or a lossy one; signed: with a session key, as
// snapthread-device runs.
Rendered RunThroughSnaps(const LinkOptions* link, bool signed_session) {
  g_now_us = 1000000;
  SimPathDevice device(ScriptedPath({{-0.02, 0.0, 0.0}, {0.02, 0.0, 0.0}}, 0.04), &FakeClock);
  EXPECT_TRUE(device.Open(nullptr));
  InMemoryTransport wire;
  std::unique_ptr<LossyTransport> lossy;
  if (link != nullptr) lossy = std::make_unique<LossyTransport>(&wire, *link, &FakeClock);
  SpringServer server(&wire, 50.0);
  server.snap_at_x_m = 0.005;
  server.snap_back_at_x_m = -0.005;
  server.snap_jump_n[0] = 1.5;

  const auth::SessionKey key = auth::SessionKey::Generate();
  const std::unique_ptr<DeviceKeys> keys = testing::DeviceKeysFor(key);
  DeviceClientConfig config;
  config.device_id = "order-test";
  config.loop.realtime = false;
  config.log_period_us = 0;
  config.clock = &FakeClock;
  if (signed_session) {
    config.keys = keys.get();
    server.SignWith(&key, auth::NewEpoch(), config.session);
  }
  DeviceClient client(&device,
                      lossy ? static_cast<DeviceTransport*>(lossy.get()) : &wire, config);
  Rendered r;
  for (int i = 0; i < kTicks; ++i) {
    g_now_us += 1000;
    client.Tick(g_now_us, 0);
    r.fx_n.push_back(device.last_force_n()[0]);
    client.Service(g_now_us);
    if (signed_session && i % 20 == 0) server.DeliverStatus();  // the server's 50 Hz status
    server.AnswerAll();
    client.Receive(0);
  }
  EXPECT_EQ(server.snaps(), kLegs);
  r.received = client.receiver().received();
  r.out_of_order = client.receiver().out_of_order();
  r.auth_rejected = client.receiver().auth_rejected();
  r.snaps_felt = client.receiver().snaps_felt();
  if (lossy) {
    r.models_reordered = lossy->models().reordered();
    r.models_lost = lossy->models().lost();
    r.poses_reordered = lossy->poses().reordered();
  }
  EXPECT_EQ(client.Summary(g_now_us).nonfinite_outputs, 0u);
  return r;
}

// Each snap as the hand feels it: one step (a slew-limited ramp) between the spring's
// slopes, so dF changes sign twice per snap (down -> up -> down, or the reverse), and once
// at each turn of the path.
void ExpectOneStepPerSnap(const Rendered& r, const std::string& what) {
  EXPECT_EQ(Steps(r.fx_n).size(), static_cast<size_t>(kLegs)) << what;
  EXPECT_EQ(CountSignChanges(r.fx_n), 2 * kLegs + (kLegs - 1)) << what;
}

TEST(DeviceModelOrderTest, EachSnapIsOneForceStepOverAPerfectLink) {
  const Rendered ref = RunThroughSnaps(nullptr, false);
  ExpectOneStepPerSnap(ref, "perfect link");
  EXPECT_EQ(ref.out_of_order, 0u);
  EXPECT_EQ(ref.snaps_felt, static_cast<uint64_t>(kLegs));
}

// Every tick of a lossy run renders what the perfect link did, except within the round
// trip after a snap (the spring model is exact, so a late model renders the same force).
void ExpectSameForceAwayFromTheSnaps(const Rendered& lossy, const Rendered& ref,
                                     const std::string& what) {
  const std::vector<size_t> steps = Steps(ref.fx_n);
  size_t next = 0, mismatches = 0;
  for (size_t i = kSettledTick; i < ref.fx_n.size(); ++i) {
    while (next < steps.size() && i >= steps[next] + 60) ++next;
    if (next < steps.size() && i + 2 >= steps[next]) continue;  // a snap, up to 60 ms late
    if (std::abs(lossy.fx_n[i] - ref.fx_n[i]) > 1e-9) ++mismatches;
  }
  EXPECT_EQ(mismatches, 0u) << what;
}

void ExpectOneStepPerSnapUnderLoss(bool signed_session, uint32_t seeds) {
  const Rendered ref = RunThroughSnaps(nullptr, signed_session);
  ExpectOneStepPerSnap(ref, "perfect link");
  uint64_t reordered = 0, dropped = 0;
  for (uint32_t seed = 1; seed <= seeds; ++seed) {
    LinkOptions link;  // 20 % loss, 5 ± 2 ms
    link.seed = seed;
    const Rendered r = RunThroughSnaps(&link, signed_session);
    const std::string what = "seed " + std::to_string(seed);
    ExpectOneStepPerSnap(r, what);
    ExpectSameForceAwayFromTheSnaps(r, ref, what);
    EXPECT_GT(r.models_lost, 1000u) << what;
    EXPECT_GT(r.poses_reordered, 500u) << what;
    reordered += r.models_reordered;
    // Signed, a stale auth_seq refuses an overtaken model before ModelOrder sees it (which
    // then drops only answers to late poses: this fake answers every pose that arrives).
    dropped += r.auth_rejected + r.out_of_order;
    if (!signed_session) {
      EXPECT_EQ(r.auth_rejected, 0u) << what;
    }
  }
  EXPECT_GT(reordered, 500u * seeds);
  EXPECT_GT(dropped, 500u * seeds);
}

TEST(DeviceModelOrderTest, EachSnapIsOneForceStepUnderLossAndReordering) {
  ExpectOneStepPerSnapUnderLoss(false, 20);
}

TEST(DeviceModelOrderTest, SignedSnapIsOneForceStepUnderLossAndReordering) {
  ExpectOneStepPerSnapUnderLoss(true, 8);
}

// ---- the real tracker on curve2d_snap ----------------------------------------------------

// The server's solve path in-process (MakeTracker, PoseToControls, BuildForceModel), with
// its pose handling: of the poses that arrived, only the newest is solved, and never one
// older than the last solved (the real server's inbox and per-device auth_seq filter).
class TrackerServer {
 public:
  TrackerServer(InMemoryTransport* wire, const Scene& scene)
      : wire_(wire), scene_(scene), tracker_(MakeTracker(scene)) {
    tracker_->Reset(scene.grasp_start);
  }

  void AnswerNewest() {
    const device_state_t* newest = nullptr;
    for (; taken_ < wire_->states.size(); ++taken_) {
      const device_state_t& s = wire_->states[taken_];
      if (s.seq > last_seq_ && (newest == nullptr || s.seq > newest->seq)) newest = &s;
    }
    if (newest == nullptr) return;
    last_seq_ = newest->seq;
    const Eigen::Vector3d p(newest->position[0], newest->position[1], newest->position[2]);
    const Eigen::Vector4d q(newest->orientation[0], newest->orientation[1],
                            newest->orientation[2], newest->orientation[3]);
    server::ForceModelInputs in;
    in.mapping = &scene_.device;
    in.model = &tracker_->model();
    in.u = messages::PoseToControls(scene_.device, scene_.grasp_layout, p, q,
                                    messages::RestGripDirection(scene_));
    in.position_m = p;
    in.result = &tracker_->Update(in.u);
    in.device_seq = newest->seq;
    in.device_utime = newest->utime;
    in.seq = ++seq_;
    const force_model_t m = server::BuildForceModel(in);
    if (m.status == force_model_t::STATUS_SNAPPED) ++snaps_;
    wire_->Deliver(m);
  }
  int snaps() const { return snaps_; }

 private:
  InMemoryTransport* wire_;
  const Scene& scene_;
  std::unique_ptr<EquilibriumTracker> tracker_;
  size_t taken_ = 0;
  int64_t last_seq_ = -1, seq_ = 0;
  int snaps_ = 0;
};

constexpr int kTrackerLegs = 6;  // 1 s each, one snap in each

// The hand moves the grasp of curve2d_snap up and down through both snaps (Y = ±3.41)
// at 15 cm/s (7.5 model units/s).
// Returns the force handed to the backend each tick, per component (x, y).
std::array<std::vector<double>, 2> RunTrackerThroughSnaps(const Scene& scene,
                                                          const LinkOptions* link) {
  g_now_us = 1000000;
  Vec lo(2), hi(2);
  lo << 9.0, -3.75;
  hi << 9.0, 3.75;
  const Eigen::Vector3d a = messages::ControlsToPosition(scene.device, scene.grasp_layout, lo);
  const Eigen::Vector3d b = messages::ControlsToPosition(scene.device, scene.grasp_layout, hi);
  SimPathDevice device(ScriptedPath({{a.x(), a.y(), a.z()}, {b.x(), b.y(), b.z()}}, 0.15),
                       &FakeClock);
  EXPECT_TRUE(device.Open(nullptr));
  InMemoryTransport wire;
  std::unique_ptr<LossyTransport> lossy;
  if (link != nullptr) lossy = std::make_unique<LossyTransport>(&wire, *link, &FakeClock);
  TrackerServer server(&wire, scene);
  DeviceClientConfig config;
  config.limits = LimitsFrom(device.capabilities(), &scene.device);
  config.loop.realtime = false;
  config.log_period_us = 0;
  config.clock = &FakeClock;
  DeviceClient client(&device,
                      lossy ? static_cast<DeviceTransport*>(lossy.get()) : &wire, config);
  std::array<std::vector<double>, 2> f;
  for (int i = 0; i < kTrackerLegs * 1000 - 20; ++i) {
    g_now_us += 1000;
    client.Tick(g_now_us, 0);
    for (int c = 0; c < 2; ++c) f[c].push_back(device.last_force_n()[c]);
    client.Service(g_now_us);
    server.AnswerNewest();
    client.Receive(0);
  }
  EXPECT_EQ(server.snaps(), kTrackerLegs);
  return f;
}

// Reversals of a rendered force (the stability suite's zig-zag filter: a move of more
// than `tolerance` back from the last extreme), after the fade-in.
int Reversals(const std::vector<double>& f, double tolerance) {
  std::vector<SweepRow> rows;
  for (size_t i = kSettledTick; i < f.size(); ++i) {
    SweepRow r;
    r.force = Vec::Constant(1, f[i]);
    rows.push_back(r);
  }
  return CountReversals(rows, 0, tolerance);
}

TEST(DeviceModelOrderTest, TrackerSnapsAreOneForceStepEachUnderLossAndReordering) {
  const char* dir = std::getenv("SNAPTHREAD_SOURCE_DIR");
  const Scene scene =
      LoadScene(std::string(dir != nullptr ? dir : "..") + "/scenes/curve2d_snap.yaml");
  // A snap changes F_x by 0.5 N and F_y by 0.2 N; 0.02 N is far above the solver's noise.
  const double kTolerance = 0.02;
  const auto ref = RunTrackerThroughSnaps(scene, nullptr);
  for (int c = 0; c < 2; ++c) {
    EXPECT_GE(Reversals(ref[c], kTolerance), kTrackerLegs) << c;  // at least the snaps
  }
  for (uint32_t seed = 1; seed <= 12; ++seed) {
    LinkOptions link;  // 20 % loss, 5 ± 2 ms
    link.seed = seed;
    const auto lossy = RunTrackerThroughSnaps(scene, &link);
    for (int c = 0; c < 2; ++c) {
      EXPECT_EQ(Reversals(lossy[c], kTolerance), Reversals(ref[c], kTolerance))
          << "component " << c << " seed " << seed;
    }
  }
}

}  // namespace
}  // namespace snapthread::device
