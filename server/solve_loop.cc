#include "solve_loop.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <utility>

#include <spdlog/spdlog.h>

#include "checkpoint.h"
#include "messages/validate.h"
#include "realtime/clock.h"
#include "server_messages.h"
#include "update_cap.h"

namespace snapthread::server {
namespace {

using SteadyClock = std::chrono::steady_clock;

std::string Format(const Vec& v) {
  std::string out;
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (i > 0) out += ", ";
    out += std::to_string(v[i]);
  }
  return out;
}

SteadyClock::duration Period(double rate_hz) {
  return std::chrono::duration_cast<SteadyClock::duration>(
      std::chrono::duration<double>(1.0 / rate_hz));
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The next time of a periodic task that ran at `now`: one period on, or one period from
// now when it fell behind (no burst).
void Advance(SteadyClock::time_point now, SteadyClock::duration period,
             SteadyClock::time_point* next) {
  *next += period;
  if (*next <= now) *next = now + period;
}

}  // namespace

SolveLoop::SolveLoop(const ServerParams& params, const messages::Channels& channels,
                     const auth::SessionKey& key, int64_t epoch, ServerTestHooks hooks,
                     ServerCounters* counters, ServerInfo* info)
    : params_(params),
      channels_(channels),
      hooks_(std::move(hooks)),
      counters_(counters),
      info_(info),
      method_override_(params.method) {
  // The scene first: a bad scene is the user's most likely mistake, reported before the
  // network is touched.
  Scene scene = LoadScene(params_.scene_path);
  session_ = MakeSession(scene, Settings());
  SetInfo(nullptr);
  if (params_.state_dir.empty()) return;
  // Checkpoints: may resume another scene and method than the start's.
  PrepareStateDir(params_.state_dir);
  // The start scene's text, as LoadScene just read it, so a checkpoint reloads the same
  // scene even when the file changes later.
  session_->scene_text = ReadText(params_.scene_path);
  const std::string path = CheckpointPath(params_.state_dir, channels_.session);
  SessionSettings settings = Settings();
  std::unique_ptr<Session> resumed =
      ResumeCheckpoint(path, key, params_, session_->scene.name, epoch, &settings);
  if (resumed) {
    method_override_ = settings.method;
    session_ = std::move(resumed);
    SetInfo(nullptr);
    resumed_ = true;
  }
  checkpoints_ =
      std::make_unique<SessionCheckpoints>(path, key, epoch, hooks_.before_checkpoint_write);
}

SessionSettings SolveLoop::Settings() const {
  return SessionSettings{method_override_, params_.time_budget_us, params_.snap_ahead};
}

void SolveLoop::SetInfo(const std::string* command) {
  info_->Set(session_->scene.name, session_->tracker->options().method, command);
}

std::string SolveLoop::Describe() const {
  return "scene '" + session_->scene.name + "' (" + session_->scene.file + "), method " +
         session_->tracker->options().method;
}

void SolveLoop::CopyCheckpointStats(ServerStats* s) const {
  if (!checkpoints_) return;
  s->checkpoints = true;
  s->resumed = resumed_;
  s->checkpoint = checkpoints_->Stats();
}

void SolveLoop::Run(ServerInbox* inbox, Publisher* publisher) {
  publisher_ = publisher;
  const auto shape_period = Period(params_.shape_rate_hz);
  const auto status_period = Period(params_.status_rate_hz);
  const auto checkpoint_period = Period(params_.checkpoint_rate_hz);
  auto now = SteadyClock::now();
  auto next_shape = now;
  auto next_status = now;
  auto next_checkpoint = checkpoints_ ? now : SteadyClock::time_point::max();
  last_status_time_ = now;
  UpdateCap cap;  // --max-update-hz / solver.max_update_hz
  while (true) {
    const double cap_hz = params_.max_update_hz > 0.0 ? params_.max_update_hz : session_->scene.max_update_hz;
    ServerInbox::Taken taken = inbox->Wait(std::min({next_shape, next_status, next_checkpoint, cap.Wake()}));
    if (taken.stop) break;
    counters_->dropped_poses.fetch_add(cap.Hold(&taken.poses));
    cap.Release(cap_hz, SteadyClock::now(), &taken.poses);
    bool changed_session = false;
    for (const command_t& command : taken.commands) {
      ApplyCommand(command);
      changed_session = true;
    }
    if (PollSceneLoad()) changed_session = true;
    RefuseForeignGrasps(&taken.poses);
    if (!taken.poses.empty()) SolveAndPublish(taken.poses);
    now = SteadyClock::now();
    if (changed_session) knot_watch_.Reset();
    knot_watch_.Tick(now, session_->scene, *session_->tracker);
    if (now >= next_shape || changed_session) {
      PublishShape();
      Advance(now, shape_period, &next_shape);
    }
    if (now >= next_status || changed_session) {
      PublishStatus();
      Advance(now, status_period, &next_status);
    }
    if (now >= next_checkpoint || (checkpoints_ && changed_session)) {
      OfferCheckpoint();
      Advance(now, checkpoint_period, &next_checkpoint);
    }
  }
  publisher_ = nullptr;
}

void SolveLoop::Finish() {
  if (checkpoints_) {
    OfferCheckpoint();  // the state at the stop, so a restart resumes exactly here
    checkpoints_->Flush();
  }
  load_.Join();  // a scene load still running (bounded by its file size and the parser)
}

void SolveLoop::OfferCheckpoint() {
  checkpoints_->Offer(*session_, counters_->updates.load(), counters_->commands_applied.load(),
                      info_);
}

void SolveLoop::SolveAndPublish(const std::vector<ReceivedPose>& poses) {
  SessionUpdate update = MapPoses(*session_, poses);
  for (size_t k = 0; k < poses.size(); ++k) {
    if (update.grasp_of[k] < 0) {
      counters_->refusals.Count(poses[k].state.sender_role, RefusalReason::kNoSuchGrasp);
      CountRejection(counters_, channels_.device_state,
                     "no grasp '" + poses[k].state.grasp + "' in scene " + session_->scene.name);
    }
  }
  if (!update.any) return;

  if (hooks_.before_update) hooks_.before_update();
  Solve(session_.get(), poses, &update);
  if (update.failed && ShouldLog(&counters_->last_solve_error_log_us)) {
    spdlog::error("server: update at u = ({}) failed: {}", Format(update.u), update.error);
  }
  if (hooks_.after_update && update.result != nullptr) hooks_.after_update(update.u, *session_->tracker);
  FollowFold(session_.get(), poses, update);

  counters_->updates.fetch_add(1);
  if (ClassifyStatus(update.result) == force_model_t::STATUS_SNAPPED ||
      (update.switched && update.result != nullptr)) {
    counters_->snaps.fetch_add(1);
    ++snaps_since_reset_;
    if (spdlog::should_log(spdlog::level::debug)) spdlog::debug("server: snap at u = ({})", Format(update.u));
  }
  status_window_.Push(update.solve_us);
  info_->RecordSolve(update.solve_us);
  // One force model per pose that named a grasp: that grasp's block of F and K.
  bool first = true;
  for (size_t k = 0; k < poses.size(); ++k) {
    if (update.grasp_of[k] < 0) continue;
    PublishGraspModel(poses[k], update.grasp_of[k], update, first);
    first = false;
  }
}

void SolveLoop::PublishGraspModel(const ReceivedPose& pose, int grasp, const SessionUpdate& update,
                                  bool first) {
  force_model_t msg = GraspForceModel(*session_, pose, grasp, update, model_seq_++);
  // Statistics of the update (counted by SolveAndPublish before any model leaves, so
  // whoever receives one sees them); the first grasp's model is the one reported.
  if (first) {
    last_status_ = msg.status;
    for (int i = 0; i < 3; ++i) last_force_n_[i] = msg.f0[i];
    if (msg.status == force_model_t::STATUS_INVALID) counters_->invalid_models.fetch_add(1);
  }
  publisher_->ForceModel(&msg, grasp, pose.key);
}

void SolveLoop::RefuseForeignGrasps(std::vector<ReceivedPose>* poses) {
  // A pose naming no grasp drives the scene's first one (FindGrasp): only the device of
  // that name may send it ("hand" for the single unnamed grasp). The gate checked the
  // poses that name their grasp.
  const auto& grasps = session_->scene.grasps;
  const std::string_view own = grasps.empty() || grasps[0].name.empty() ? std::string_view("hand")
                                                                       : std::string_view(grasps[0].name);
  std::erase_if(*poses, [&](const ReceivedPose& p) {
    if (!p.state.grasp.empty() || p.state.sender_name == own) return false;
    counters_->refusals.Count(p.state.sender_role, RefusalReason::kWrongGrasp);
    CountRejection(counters_, channels_.device_state,
                   "wrong-grasp: device '" + p.state.sender_name + "' sent a pose for grasp '" +
                       std::string(own) + "'");
    return true;
  });
}

void SolveLoop::PublishShape() {
  const EquilibriumTracker& tracker = *session_->tracker;
  ShapeInputs in;
  in.scene = session_->scene.name;
  in.mapping = &session_->scene.device;
  in.model = &tracker.model();
  in.x = tracker.state();
  in.u = tracker.control();
  in.force_model_units = tracker.last().force;
  in.force_newtons = Eigen::Vector3d(last_force_n_[0], last_force_n_[1], last_force_n_[2]);
  in.status = last_status_;
  in.snaps = snaps_since_reset_;
  in.knot = knot_watch_.name();
  in.seq = shape_seq_++;
  in.utime = realtime::RealtimeMicros();
  thread_shape_t msg = BuildShape(in);
  std::string why;
  if (!messages::Validate(msg, &why)) {
    if (ShouldLog(&counters_->last_solve_error_log_us)) spdlog::error("server: bad shape not sent: {}", why);
    return;
  }
  publisher_->Shape(&msg);
}

void SolveLoop::PublishStatus() {
  const auto now = SteadyClock::now();
  const double dt = std::chrono::duration<double>(now - last_status_time_).count();
  const int64_t updates = counters_->updates.load();
  const realtime::PercentileSummary window = status_window_.Compute();
  StatusInputs in;
  in.scene = session_->scene.name;
  in.method = session_->tracker->options().method;
  in.summary = &session_->tracker->last().summary;
  in.status = last_status_;
  in.update_rate_hz = dt > 0.0 ? static_cast<double>(updates - updates_at_last_status_) / dt : 0.0;
  in.solve_us_p50 = window.p50;
  in.solve_us_p99 = window.p99;
  in.updates = updates;
  in.snaps = counters_->snaps.load();
  in.dropped_poses = counters_->dropped_poses.load();
  in.rejected_messages = counters_->rejected_messages.load();
  in.refusals = counters_->refusals.Format();
  in.contacts = static_cast<int32_t>(session_->tracker->ActiveContacts().size());
  in.knot = knot_watch_.name();
  in.knot_determinant = knot_watch_.determinant();
  in.max_update_hz = params_.max_update_hz > 0.0 ? params_.max_update_hz : session_->scene.max_update_hz;
  in.seq = status_seq_++;
  in.utime = realtime::RealtimeMicros();
  solver_status_t msg = BuildSolverStatus(in);
  status_window_.Clear();
  updates_at_last_status_ = updates;
  last_status_time_ = now;
  publisher_->SolverStatus(&msg);
}

}  // namespace snapthread::server
