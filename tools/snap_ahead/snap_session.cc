#include "snap_session.h"

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>

#include "device_client.h"
#include "fold_boundary.h"
#include "messages/pose_mapping.h"
#include "models/registry.h"
#include "scripted_path.h"
#include "server_messages.h"
#include "sim_path_device.h"
#include "tracking/make_tracker.h"

namespace snapthread::snap_ahead {
namespace {

int64_t g_now_us = 0;
int64_t FakeClock() { return g_now_us; }

// The wire between the two halves: the newest pose (the server's inbox keeps only that)
// and the force models not yet polled by the device.
class Wire final : public device::DeviceTransport {
 public:
  bool PublishDeviceState(const device_state_t& msg) override {
    newest = msg;
    return true;
  }
  bool PublishDeviceStatus(const device_status_t&) override { return true; }
  int PollForceModels(int, const ForceModelSink& sink) override {
    for (const auto& bytes : models) sink(bytes.data(), static_cast<int>(bytes.size()));
    const int n = static_cast<int>(models.size());
    models.clear();
    return n;
  }
  int PollSolverStatus(const StatusSink&) override { return 0; }

  std::optional<device_state_t> newest;
  std::vector<std::vector<uint8_t>> models;
};

// The server's half of one update: the newest pose (taken off the wire) to controls, the
// tracker's update (resumed on the far branch first when the device switched there), and
// the force model back on the wire.
void ServeNewestPose(const Scene& scene, const Eigen::Vector3d& rest, EquilibriumTracker* tracker,
                     server::FoldBoundary* fold, int64_t* model_seq, Wire* wire) {
  const device_state_t pose = *wire->newest;
  wire->newest.reset();
  const Eigen::Vector3d p(pose.position[0], pose.position[1], pose.position[2]);
  const Eigen::Vector4d q(pose.orientation[0], pose.orientation[1], pose.orientation[2],
                          pose.orientation[3]);
  const Vec u = messages::PoseToControls(scene.device, scene.grasp_layout, p, q, rest);
  Vec x_after, u_after;
  if (fold && fold->TakeSwitch(pose.snap_fold_id, &x_after, &u_after)) tracker->Resume(x_after, u_after);
  const TrackResult& r = tracker->Update(u);
  if (fold) {
    fold->AfterUpdate(*tracker, u, q);
    fold->WaitForSearch();
  }
  server::ForceModelInputs in;
  in.mapping = &scene.device;
  in.model = &tracker->model();
  in.u = u;
  in.position_m = p;
  in.result = &r;
  in.layout = &scene.grasp_layout;
  in.device_seq = pose.seq;
  in.device_utime = pose.utime;
  in.seq = (*model_seq)++;
  force_model_t msg = server::BuildForceModel(in);
  if (fold) fold->Fill(&msg);
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  wire->models.push_back(std::move(bytes));
}

}  // namespace

SessionResult RunSession(const Scene& scene, const SessionOptions& options) {
  if (!(options.server_hz > 0.0) || !(options.speed_m_per_s > 0.0))
    throw std::invalid_argument("RunSession: server_hz and speed_m_per_s must be > 0");
  g_now_us = 1000000;
  device::ScriptedPath path = device::ScriptedPath::FromScene(scene, options.speed_m_per_s);
  device::SimPathDevice hand(path, &FakeClock);
  std::string error;
  if (!hand.Open(&error)) throw std::runtime_error(error);
  Wire wire;
  device::DeviceClientConfig config;
  config.device_id = "snap-ahead-session";
  config.limits = device::LimitsFrom(hand.capabilities(), &scene.device);
  config.loop.realtime = false;
  config.log_period_us = 0;
  config.clock = &FakeClock;
  config.snap_ahead = options.snap_ahead;
  // As snapthread-device sets them: the sim-path hand senses its orientation and renders
  // torque (the grip's, thread3d_loop).
  config.device_has_orientation = hand.capabilities().has_orientation;
  config.device_torque_output = hand.capabilities().has_torque_output;
  device::DeviceClient client(&hand, &wire, config);

  // The server: its scene -> tracker path, started where the hand starts.
  std::unique_ptr<EquilibriumTracker> tracker = MakeTracker(scene);
  tracker->Reset(scene.grasp_start);
  std::unique_ptr<server::FoldBoundary> fold;
  if (options.snap_ahead) fold = std::make_unique<server::FoldBoundary>(scene);
  const Eigen::Vector3d rest = messages::RestGripDirection(scene);

  const double duration_s =
      options.duration_s > 0.0 ? options.duration_s : path.duration_s();
  const int64_t ticks = static_cast<int64_t>(std::llround(duration_s * 1000.0));
  const double period_us = 1e6 / options.server_hz;
  double next_solve_us = static_cast<double>(g_now_us);
  int64_t model_seq = 0;
  SessionResult out;
  out.ticks.reserve(static_cast<size_t>(ticks));
  for (int64_t i = 0; i < ticks; ++i) {
    g_now_us += 1000;
    client.Tick(g_now_us, 0);
    const double* f = hand.last_force_n();
    const double* tq = hand.last_torque_nm();
    device::DeviceState state;
    hand.Read(&state);
    out.ticks.push_back({Eigen::Vector3d(state.position_m[0], state.position_m[1], state.position_m[2]),
                         Eigen::Vector4d(state.orientation[0], state.orientation[1], state.orientation[2],
                                         state.orientation[3]),
                         Eigen::Vector3d(f[0], f[1], f[2]),
                         Eigen::Vector3d(tq[0], tq[1], tq[2])});
    client.Service(g_now_us);  // publishes this tick's pose
    if (wire.newest && static_cast<double>(g_now_us) >= next_solve_us) {
      next_solve_us += period_us;
      ServeNewestPose(scene, rest, tracker.get(), fold.get(), &model_seq, &wire);
      ++out.models;
    }
    client.Receive(0);  // rendered from the next tick on
  }
  out.snap_ahead_switches = client.Summary(g_now_us).snap_ahead_switches;
  out.snaps_felt = client.receiver().snaps_felt();
  out.searches = fold ? static_cast<unsigned long long>(fold->searches()) : 0;
  return out;
}

std::vector<ForceJump> ForceJumps(const std::vector<TickRow>& ticks, double step_n_per_tick,
                                  double step_nm_per_tick, int settle_ticks) {
  std::vector<ForceJump> jumps;
  bool in_step = false;
  for (size_t i = static_cast<size_t>(std::max(settle_ticks, 1)); i < ticks.size(); ++i) {
    const bool big = (ticks[i].force_n - ticks[i - 1].force_n).norm() > step_n_per_tick ||
                     (step_nm_per_tick > 0.0 &&
                      (ticks[i].torque_nm - ticks[i - 1].torque_nm).norm() > step_nm_per_tick);
    if (big && !in_step) jumps.push_back({static_cast<int>(i), ticks[i].position_m, 0.0, 0.0});
    if (big) {
      const TickRow& before = ticks[jumps.back().tick - 1];
      jumps.back().size_n = (ticks[i].force_n - before.force_n).norm();
      jumps.back().size_nm = (ticks[i].torque_nm - before.torque_nm).norm();
    }
    in_step = big;
  }
  return jumps;
}

std::vector<Vec> TrueFolds(const Scene& scene, double step) {
  std::unique_ptr<EquilibriumTracker> tracker = MakeTracker(scene);
  tracker->Reset(scene.grasp_start);
  std::vector<Vec> folds;
  Vec u = scene.grasp_start;
  const GraspLayout& layout = scene.grasp_layout;
  const int dim = layout.spatial_dimension;
  for (size_t w = 1; w < scene.path.size(); ++w) {
    const Vec a = scene.path[w - 1], b = scene.path[w];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int k = 1; k <= n; ++k) {
      const Vec before = u;
      const Vec x_before = tracker->state();
      u = a + (b - a) * (static_cast<double>(k) / n);
      if (!tracker->Update(u).snapped) continue;
      // Again from the last state on the branch, a thousand times finer.
      tracker->Resume(x_before, before);
      Vec lo = before;
      for (int j = 1; j <= 1000; ++j) {
        const Vec fine = before + (u - before) * (j / 1000.0);
        if (tracker->Update(fine).snapped) {
          Vec fold = 0.5 * (lo + fine);
          // The model sees a grip direction's direction only (thread3d_model.cc).
          if (layout.grip_direction && fold.size() >= dim + 3) fold.segment(dim, 3).normalize();
          folds.push_back(fold);
          break;
        }
        lo = fine;
      }
      tracker->Update(u);  // on along the path from the other branch
    }
  }
  return folds;
}

Vec TickControls(const Scene& scene, const TickRow& tick) {
  return messages::PoseToControls(scene.device, scene.grasp_layout, tick.position_m, tick.orientation,
                                  messages::RestGripDirection(scene));
}

double SnapErrorTicks(const Scene& scene, const std::vector<TickRow>& ticks, const ForceJump& jump,
                      const Vec& fold) {
  if (jump.tick < 1 || static_cast<size_t>(jump.tick) >= ticks.size()) return NAN;
  const Vec u = TickControls(scene, ticks[jump.tick]);
  const Vec v = u - TickControls(scene, ticks[jump.tick - 1]);
  const double v2 = v.squaredNorm();
  if (!(v2 > 0.0) || u.size() != fold.size()) return NAN;
  return (u - fold).dot(v) / v2;
}

}  // namespace snapthread::snap_ahead
