#include "session.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <stdexcept>
#include <string>

#include <spdlog/spdlog.h>

#include "grasp_poses.h"
#include "messages/pose_mapping.h"
#include "messages/validate.h"
#include "realtime/clock.h"
#include "server_messages.h"
#include "solvers/registry.h"
#include "tracking/make_tracker.h"

namespace snapthread::server {

std::unique_ptr<Session> MakeSession(const Scene& scene, const SessionSettings& settings) {
  auto session = std::make_unique<Session>();
  session->scene = scene;
  SolverOptions options = scene.solver;
  if (!settings.method.empty()) {
    if (SolverRegistry::Global().Find(settings.method) == nullptr) {
      throw std::invalid_argument("unknown method '" + settings.method + "'");
    }
    options.method = settings.method;
  }
  if (settings.time_budget_us >= 0.0) options.max_time_us = settings.time_budget_us;
  session->scene.solver = options;
  // The one scene -> tracker path (SceneError for invalid parameters or options).
  session->tracker = MakeTracker(session->scene);
  // Snap-ahead's boundary is in the one grasp's position space.
  if (settings.snap_ahead && scene.grasps.size() <= 1)
    session->fold = std::make_unique<FoldBoundary>(session->scene);
  // Every grasp takes the layout's controls (several grasps concatenate theirs).
  const int grasp_controls =
      scene.grasp_layout.NumControls() * std::max<int>(1, static_cast<int>(scene.grasps.size()));
  if (grasp_controls != session->tracker->model().NumControls()) {
    throw SceneError(scene.file + ": the scene's grasp layout has " +
                     std::to_string(grasp_controls) + " controls, model " +
                     std::string(session->tracker->model().Name()) + " has " +
                     std::to_string(session->tracker->model().NumControls()));
  }
  session->rest_direction = messages::RestGripDirection(scene);
  session->tracker->Reset(scene.grasp_start);
  return session;
}

SessionUpdate MapPoses(const Session& session, const std::vector<ReceivedPose>& poses) {
  SessionUpdate update;
  update.u = session.tracker->control();
  update.grasp_of =
      ApplyGraspPoses(session.scene, session.rest_direction, poses, &update.u, &update.renamed);
  update.any = std::any_of(update.grasp_of.begin(), update.grasp_of.end(),
                           [](int grasp) { return grasp >= 0; });
  return update;
}

void Solve(Session* session, const std::vector<ReceivedPose>& poses, SessionUpdate* update) {
  EquilibriumTracker& tracker = *session->tracker;
  update->result = nullptr;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    // The device felt the post-snap model of the current fold: start on the new branch.
    Vec x_after, u_after;
    update->switched = false;
    for (const ReceivedPose& pose : poses) {
      if (session->fold && session->fold->TakeSwitch(pose.state.snap_fold_id, &x_after, &u_after)) {
        tracker.Resume(x_after, u_after);
        update->switched = true;  // the snap happened (felt ahead by the device): counted as one
        break;
      }
    }
    // A grasp's rotation vector moved to another name of its rotation (grasp_poses.h).
    if (!update->switched && update->renamed != tracker.control()) tracker.RelabelControls(update->renamed);
    update->result = &tracker.Update(update->u);
  } catch (const std::exception& e) {
    update->failed = true;
    update->error = e.what();
  }
  update->solve_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
}

void FollowFold(Session* session, const std::vector<ReceivedPose>& poses,
                const SessionUpdate& update) {
  if (!session->fold || update.result == nullptr) return;
  // The hand's orientation: a fold reached by turning is sent in its pose chart.
  Eigen::Vector4d q(1.0, 0.0, 0.0, 0.0);
  for (size_t k = 0; k < poses.size(); ++k) {
    if (update.grasp_of[k] >= 0) {
      const double* o = poses[k].state.orientation;
      q = Eigen::Vector4d(o[0], o[1], o[2], o[3]);
    }
  }
  session->fold->AfterUpdate(*session->tracker, update.u, q);
}

force_model_t GraspForceModel(const Session& session, const ReceivedPose& pose, int grasp,
                              const SessionUpdate& update, int64_t seq) {
  const Model& model = session.tracker->model();
  const Scene& scene = session.scene;
  const DeviceMapping mapping = GraspDeviceMapping(scene, grasp);
  ForceModelInputs in;
  in.mapping = &mapping;
  in.model = &model;
  in.u = update.u;
  in.position_m = Eigen::Vector3d(pose.state.position[0], pose.state.position[1], pose.state.position[2]);
  in.result = update.result;
  if (!scene.grasps.empty()) {
    in.grasp_offset = scene.grasps[grasp].offset;
    in.grasp_controls = scene.grasp_layout.NumControls();
  }
  in.layout = &scene.grasp_layout;
  in.device_seq = pose.state.seq;
  in.device_utime = pose.state.utime;
  in.server_receive_utime = pose.receive_utime;
  in.solve_us = update.solve_us;
  in.seq = seq;
  in.utime = realtime::RealtimeMicros();
  force_model_t msg = BuildForceModel(in);
  // The first model on the branch the device switched to answers the snap.
  if (update.switched &&
      (msg.status == force_model_t::STATUS_REGULAR || msg.status == force_model_t::STATUS_NEAR_FOLD)) {
    msg.status = force_model_t::STATUS_SNAPPED;
  }
  std::string why;
  if (!messages::Validate(msg, &why)) {
    // BuildForceModel guarantees finiteness; this is the last line before the device.
    spdlog::error("server: refusing to publish an invalid force model: {}", why);
    msg = BuildForceModel(ForceModelInputs{in.mapping, in.model, in.u, Eigen::Vector3d::Zero(),
                                           nullptr, in.device_seq, in.device_utime,
                                           in.server_receive_utime, 0.0, in.seq, in.utime,
                                           in.grasp_offset, in.grasp_controls, in.layout});
  }
  if (session.fold) session.fold->Fill(&msg);
  msg.grasp = scene.grasps.empty() ? std::string() : scene.grasps[grasp].name;
  return msg;
}

}  // namespace snapthread::server
