#include "server.h"

#include "grasp_poses.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <optional>
#include <utility>
#include <vector>

#include <spdlog/spdlog.h>

#include "auth/message_gate.h"
#include "auth/message_mac.h"
#include "messages/pose_mapping.h"
#include "scene_dir.h"
#include "server_messages.h"
#include "server_session.h"
#include "update_cap.h"
#include "tracking/make_tracker.h"
#include "realtime/clock.h"
#include "messages/lcm_url.h"
#include "messages/subscribe.h"
#include "messages/validate.h"
#include "solvers/registry.h"

namespace snapthread::server {
namespace {

using SteadyClock = std::chrono::steady_clock;

constexpr int64_t kLogPeriodUs = 1000000;  // rate limit for repeated warnings: 1 per second
constexpr int kHandleTimeoutMs = 50;       // how long Stop() may wait for the receive thread

int64_t SteadyMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             SteadyClock::now().time_since_epoch())
      .count();
}

// True at most once per kLogPeriodUs per *last (any thread).
bool ShouldLog(std::atomic<int64_t>* last) {
  const int64_t now = SteadyMicros();
  int64_t prev = last->load(std::memory_order_relaxed);
  if (now - prev < kLogPeriodUs && prev != 0) return false;
  return last->compare_exchange_strong(prev, now);
}

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

auth::SessionKey LoadServerKey(const auth::KeyLocation& where, bool create, bool* created) {
  if (!create) return auth::LoadKey(where);
  auth::LoadedKey loaded = auth::LoadOrCreateKey(where);
  *created = loaded.created;
  return std::move(loaded.key);
}

}  // namespace

Server::Server(const ServerParams& params, lcm::LCM* lcm, ServerTestHooks hooks)
    : params_(params),
      key_location_(auth::ResolveKeyPath(params.key_path)),
      key_(LoadServerKey(key_location_, params.create_key, &key_created_)),
      epoch_(auth::NewEpoch()),
      hooks_(std::move(hooks)) {
  std::string error;
  if (!params_.IsValid(&error)) throw std::invalid_argument(error);
  command_filter_.SetEpoch(epoch_);  // commands must carry this start's epoch
  channels_ = messages::Channels(params_.session);
  method_override_ = params_.method;
  if (params_.scene_dir.empty()) params_.scene_dir = DefaultSceneDir();

  // The scene first: a bad scene is the user's most likely mistake, report it before
  // touching the network.
  Scene scene = LoadScene(params_.scene_path);
  session_ = MakeSession(scene);
  SetInfo(session_->scene.name, session_->tracker->options().method, nullptr);
  SetUpCheckpoints();  // may resume another scene and method: after the start scene loaded

  if (lcm != nullptr) {
    lcm_ = lcm;
    lcm_url_ = "(provided)";
  } else {
    lcm_url_ = messages::WithReceiveBuffer(messages::ResolveLcmUrl(params_.lcm_url),
                                             messages::kServiceBufferBytes);
    owned_lcm_ = std::make_unique<lcm::LCM>(lcm_url_);
    if (!owned_lcm_->good()) {
      throw LcmInitError("LCM failed to start on " + lcm_url_ + ": " +
                         messages::LcmStartHint(lcm_url_));
    }
    lcm_ = owned_lcm_.get();
  }
}

Server::~Server() { Stop(); }

std::unique_ptr<Server::Session> Server::MakeSession(const Scene& scene) const {
  auto session = std::make_unique<Session>();
  session->scene = scene;
  SolverOptions options = scene.solver;
  if (!method_override_.empty()) {
    if (SolverRegistry::Global().Find(method_override_) == nullptr) {
      throw std::invalid_argument("unknown method '" + method_override_ + "'");
    }
    options.method = method_override_;
  }
  if (params_.time_budget_us >= 0.0) options.max_time_us = params_.time_budget_us;
  session->scene.solver = options;
  // The one scene -> tracker path (SceneError for invalid parameters or options).
  session->tracker = MakeTracker(session->scene);
  // Snap-ahead's boundary is in the one grasp's position space (issue 17).
  if (params_.snap_ahead && scene.grasps.size() <= 1)
    session->fold = std::make_unique<FoldBoundary>(session->scene);
  // Every grasp takes the layout's controls (issue 15: several grasps concatenate theirs).
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

void Server::SetInfo(const std::string& scene, const std::string& method,
                     const std::string* command) {
  std::lock_guard<std::mutex> lock(info_mutex_);
  scene_name_ = scene;
  method_name_ = method;
  if (command != nullptr) last_command_message_ = *command;
}

void Server::Start() {
  if (started_) return;
  started_ = true;
  state_sub_ = messages::Subscribe<&Server::HandleDeviceState>(lcm_, channels_.device_state, this);
  command_sub_ = messages::Subscribe<&Server::HandleCommand>(lcm_, channels_.command, this);
  running_ = true;
  solve_thread_ = std::thread([this] { SolveLoop(); });
  receive_thread_ = std::thread([this] { ReceiveLoop(); });
  spdlog::info("server: session {} on {}, scene '{}' ({}), method {}", channels_.session,
               lcm_url_, session_->scene.name, session_->scene.file,
               session_->tracker->options().method);
  spdlog::info("server: {} session key {} ({}), key id {}, epoch {:016x}",
               key_created_ ? "created a new" : "using the", key_location_.path,
               key_location_.origin, key_.Id(), static_cast<uint64_t>(epoch_));
  if (key_created_) {
    spdlog::info("server: copy {} to every machine of the session (scp -p; mode 0600) and "
                 "pass it with --key or SNAPTHREAD_KEY_FILE", key_location_.path);
  }
}

void Server::Stop() {
  if (!started_ || !running_.exchange(false)) return;
  stop_ = true;
  inbox_.RequestStop();
  if (receive_thread_.joinable()) receive_thread_.join();
  if (solve_thread_.joinable()) solve_thread_.join();
  if (checkpoint_writer_) {
    OfferCheckpoint();  // the state at the stop, so a restart resumes exactly here
    checkpoint_writer_->Flush();
  }
  load_.Join();  // a scene load still running (bounded by its file size and the parser)
  if (state_sub_ != nullptr) lcm_->unsubscribe(state_sub_);
  if (command_sub_ != nullptr) lcm_->unsubscribe(command_sub_);
  state_sub_ = command_sub_ = nullptr;
}

// ---------------------------------------------------------------- receive thread

void Server::ReceiveLoop() {
  while (!stop_.load()) {
    if (lcm_->handleTimeout(kHandleTimeoutMs) < 0) {
      // An LCM error (socket gone): do not spin on it.
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
}

void Server::Reject(const std::string& channel, const std::string& why) {
  const int64_t total = rejected_messages_.fetch_add(1) + 1;
  if (ShouldLog(&last_reject_log_us_)) {
    spdlog::warn("server: dropped a bad message on {}: {} ({} rejected so far)", channel, why,
                 total);
  }
}

void Server::RejectAuth(auth::FreshnessFilter* filter) {
  rejected_messages_.fetch_add(1);
  std::string line;
  if (filter->TakeLogLine(SteadyMicros(), &line)) spdlog::warn("server: refused {}", line);
}

auth::FreshnessFilter* Server::DeviceFilter(const std::string& device_id) {
  auto it = device_filters_.find(device_id);
  if (it != device_filters_.end()) return it->second.get();
  if (device_filters_.size() >= kMaxDevices) return nullptr;
  auto filter = std::make_unique<auth::FreshnessFilter>(
      "DEVICE_STATE of " + device_id, auth::FreshnessFilter::EpochPolicy::kFixed, epoch_);
  return device_filters_.emplace(device_id, std::move(filter)).first->second.get();
}

void Server::HandleDeviceState(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  try {
    ReceivedPose sample;
    std::string why;
    if (!messages::DecodeAndValidate(rbuf, &sample.state, &why)) {
      Reject(channel, why);
      return;
    }
    // The MAC first: only a key holder's pose may create a per-device filter.
    if (!auth::VerifyEncoded(rbuf->data, rbuf->data_size, channel, key_)) {
      pose_mac_filter_.Reject(auth::Reason::kBadMac);
      RejectAuth(&pose_mac_filter_);
      return;
    }
    auth::FreshnessFilter* filter = DeviceFilter(sample.state.device_id);
    if (filter == nullptr) {
      Reject(channel, "more than " + std::to_string(kMaxDevices) + " devices");
      return;
    }
    if (filter->Admit(sample.state.epoch, sample.state.auth_seq) != auth::Reason::kAccepted) {
      RejectAuth(filter);
      return;
    }
    sample.receive_utime = realtime::RealtimeMicros();
    poses_received_.fetch_add(1);
    if (inbox_.PutPose(sample)) dropped_poses_.fetch_add(1);
  } catch (...) {
    // Only allocation can throw here; an LCM handler must not let it escape.
    rejected_messages_.fetch_add(1);
  }
}

void Server::HandleCommand(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  try {
    command_t command;
    std::string why;
    if (!messages::DecodeAndValidate(rbuf, &command, &why)) {
      Reject(channel, why);
      return;
    }
    if (auth::Admit(rbuf->data, rbuf->data_size, command, channel, key_, &command_filter_) !=
        auth::Reason::kAccepted) {
      RejectAuth(&command_filter_);
      return;
    }
    if (!inbox_.PushCommand(command)) {
      commands_refused_.fetch_add(1);
      if (ShouldLog(&last_reject_log_us_)) {
        spdlog::warn("server: command queue full, refused a command on {}", channel);
      }
    }
  } catch (...) {
    rejected_messages_.fetch_add(1);
  }
}

// ---------------------------------------------------------------- solve thread

template <class Msg>
bool Server::SignForChannel(Msg* msg, const std::string& channel) {
  if (auth::Sign(msg, channel, epoch_, auth_seq_.Next(), key_)) return true;
  publish_failures_.fetch_add(1);
  if (ShouldLog(&last_solve_error_log_us_)) {
    spdlog::error("server: could not sign a message for {}; not sent", channel);
  }
  return false;
}

void Server::SolveLoop() {
  const auto shape_period = Period(params_.shape_rate_hz);
  const auto status_period = Period(params_.status_rate_hz);
  const auto checkpoint_period = Period(params_.checkpoint_rate_hz);
  auto now = SteadyClock::now();
  auto next_shape = now;
  auto next_status = now;
  auto next_checkpoint = checkpoint_writer_ ? now : SteadyClock::time_point::max();
  last_status_time_ = now;
  UpdateCap cap;  // --max-update-hz / solver.max_update_hz
  while (true) {
    const double cap_hz = params_.max_update_hz > 0.0 ? params_.max_update_hz : session_->scene.max_update_hz;
    ServerInbox::Taken taken = inbox_.Wait(std::min({next_shape, next_status, next_checkpoint, cap.Wake()}));
    if (taken.stop) break;
    dropped_poses_.fetch_add(cap.Hold(&taken.poses));
    cap.Release(cap_hz, SteadyClock::now(), &taken.poses);
    bool changed_session = false;
    for (const command_t& command : taken.commands) {
      ApplyCommand(command);
      changed_session = true;
    }
    if (PollSceneLoad()) changed_session = true;
    if (!taken.poses.empty()) SolveAndPublish(taken.poses);
    now = SteadyClock::now();
    if (changed_session) knot_watch_.Reset();
    knot_watch_.Tick(now, session_->scene, *session_->tracker);
    if (now >= next_shape || changed_session) {
      PublishShape();
      next_shape += shape_period;
      if (next_shape <= now) next_shape = now + shape_period;  // fell behind: no burst
    }
    if (now >= next_status || changed_session) {
      PublishStatus();
      next_status += status_period;
      if (next_status <= now) next_status = now + status_period;
    }
    if (now >= next_checkpoint || (checkpoint_writer_ && changed_session)) {
      OfferCheckpoint();
      next_checkpoint += checkpoint_period;
      if (next_checkpoint <= now) next_checkpoint = now + checkpoint_period;
    }
  }
}

void Server::SolveAndPublish(const std::vector<ReceivedPose>& poses) {
  EquilibriumTracker& tracker = *session_->tracker;
  const Scene& scene = session_->scene;
  // Each pose moves its own grasp (grasp_poses.h); the others keep their controls.
  Vec u = tracker.control();
  Vec renamed;
  const std::vector<int> grasp_of = ApplyGraspPoses(scene, session_->rest_direction, poses, &u, &renamed);
  bool any = false;
  for (size_t k = 0; k < poses.size(); ++k) {
    if (grasp_of[k] >= 0) {
      any = true;
    } else {
      Reject(channels_.device_state, "no grasp '" + poses[k].state.grasp + "' in scene " + scene.name);
    }
  }
  if (!any) return;

  if (hooks_.before_update) hooks_.before_update();
  const TrackResult* result = nullptr;
  const auto t0 = SteadyClock::now();
  try {
    // The device felt the post-snap model of the current fold: start on the new branch.
    Vec x_after, u_after;
    switched_ = false;
    for (const ReceivedPose& pose : poses) {
      if (session_->fold && session_->fold->TakeSwitch(pose.state.snap_fold_id, &x_after, &u_after)) {
        tracker.Resume(x_after, u_after);
        switched_ = true;  // the snap happened (felt ahead by the device): counted as one
        break;
      }
    }
    // A grasp's rotation vector moved to another name of its rotation (grasp_poses.h).
    if (!switched_ && renamed != tracker.control()) tracker.RelabelControls(renamed);
    result = &tracker.Update(u);
  } catch (const std::exception& e) {
    if (ShouldLog(&last_solve_error_log_us_)) {
      spdlog::error("server: update at u = ({}) failed: {}", Format(u), e.what());
    }
  }
  const double solve_us = std::chrono::duration<double, std::micro>(SteadyClock::now() - t0).count();
  if (hooks_.after_update && result != nullptr) hooks_.after_update(u, tracker);
  if (session_->fold && result != nullptr) {
    // The hand's orientation: a fold reached by turning is sent in its pose chart.
    Eigen::Vector4d q(1.0, 0.0, 0.0, 0.0);
    for (size_t k = 0; k < poses.size(); ++k) {
      if (grasp_of[k] >= 0) {
        const double* o = poses[k].state.orientation;
        q = Eigen::Vector4d(o[0], o[1], o[2], o[3]);
      }
    }
    session_->fold->AfterUpdate(tracker, u, q);
  }

  updates_.fetch_add(1);
  if (ClassifyStatus(result) == force_model_t::STATUS_SNAPPED || (switched_ && result != nullptr)) {
    snaps_.fetch_add(1);
    ++snaps_since_reset_;
    if (spdlog::should_log(spdlog::level::debug)) spdlog::debug("server: snap at u = ({})", Format(u));
  }
  status_window_.Push(solve_us);
  {
    const int64_t now_us = SteadyMicros();
    std::lock_guard<std::mutex> lock(info_mutex_);
    run_window_.Push(solve_us);
    if (first_update_us_ == 0) first_update_us_ = now_us;
    last_update_us_ = now_us;
  }
  // One force model per pose that named a grasp: that grasp's block of F and K.
  bool first = true;
  for (size_t k = 0; k < poses.size(); ++k) {
    if (grasp_of[k] < 0) continue;
    PublishGraspModel(poses[k], grasp_of[k], u, result, solve_us, first);
    first = false;
  }
}

void Server::PublishGraspModel(const ReceivedPose& pose, int grasp, const Vec& u, const TrackResult* result,
                               double solve_us, bool first) {
  const Model& model = session_->tracker->model();
  const Scene& scene = session_->scene;
  const DeviceMapping mapping = GraspDeviceMapping(scene, grasp);
  ForceModelInputs in;
  in.mapping = &mapping;
  in.model = &model;
  in.u = u;
  in.position_m = Eigen::Vector3d(pose.state.position[0], pose.state.position[1], pose.state.position[2]);
  in.result = result;
  if (!scene.grasps.empty()) {
    in.grasp_offset = scene.grasps[grasp].offset;
    in.grasp_controls = scene.grasp_layout.NumControls();
  }
  in.layout = &scene.grasp_layout;
  in.device_seq = pose.state.seq;
  in.device_utime = pose.state.utime;
  in.server_receive_utime = pose.receive_utime;
  in.solve_us = solve_us;
  in.seq = model_seq_++;
  in.utime = realtime::RealtimeMicros();
  force_model_t msg = BuildForceModel(in);
  // The first model on the branch the device switched to answers the snap.
  if (switched_ && (msg.status == force_model_t::STATUS_REGULAR || msg.status == force_model_t::STATUS_NEAR_FOLD)) {
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
  if (session_->fold) session_->fold->Fill(&msg);
  msg.grasp = scene.grasps.empty() ? std::string() : scene.grasps[grasp].name;
  // Statistics of the update (counted by SolveAndPublish before any model leaves, so
  // whoever receives one sees them); the first grasp's model is the one reported.
  if (first) {
    last_status_ = msg.status;
    for (int i = 0; i < 3; ++i) last_force_n_[i] = msg.f0[i];
    if (msg.status == force_model_t::STATUS_INVALID) invalid_models_.fetch_add(1);
  }
  if (!SignForChannel(&msg, channels_.force_model)) return;
  if (lcm_->publish(channels_.force_model, &msg) != 0) publish_failures_.fetch_add(1);
}

void Server::PublishShape() {
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
    if (ShouldLog(&last_solve_error_log_us_)) spdlog::error("server: bad shape not sent: {}", why);
    return;
  }
  if (!SignForChannel(&msg, channels_.shape)) return;
  if (lcm_->publish(channels_.shape, &msg) != 0) {
    publish_failures_.fetch_add(1);
    return;
  }
  shapes_published_.fetch_add(1);
}

void Server::PublishStatus() {
  const auto now = SteadyClock::now();
  const double dt = std::chrono::duration<double>(now - last_status_time_).count();
  const int64_t updates = updates_.load();
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
  in.snaps = snaps_.load();
  in.dropped_poses = dropped_poses_.load();
  in.rejected_messages = rejected_messages_.load();
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
  if (!SignForChannel(&msg, channels_.solver_status)) return;
  if (lcm_->publish(channels_.solver_status, &msg) != 0) {
    publish_failures_.fetch_add(1);
    return;
  }
  statuses_published_.fetch_add(1);
}

// ---------------------------------------------------------------- statistics

ServerStats Server::Stats() const {
  ServerStats s;
  s.poses_received = poses_received_.load();
  s.updates = updates_.load();
  s.invalid_models = invalid_models_.load();
  s.snaps = snaps_.load();
  s.dropped_poses = dropped_poses_.load();
  s.rejected_messages = rejected_messages_.load();
  s.commands_applied = commands_applied_.load();
  s.commands_refused = commands_refused_.load();
  s.shapes_published = shapes_published_.load();
  s.statuses_published = statuses_published_.load();
  s.publish_failures = publish_failures_.load();
  std::lock_guard<std::mutex> lock(info_mutex_);
  const realtime::PercentileSummary window = run_window_.Compute();
  s.solve_us_p50 = window.p50;
  s.solve_us_p99 = window.p99;
  const double span_s = 1e-6 * static_cast<double>(last_update_us_ - first_update_us_);
  s.update_rate_hz = (window.count > 1 && span_s > 0.0)
                         ? static_cast<double>(s.updates - 1) / span_s
                         : 0.0;
  s.scene = scene_name_;
  s.method = method_name_;
  s.last_command_message = last_command_message_;
  if (checkpoint_writer_) {
    s.checkpoints = true;
    s.resumed = resumed_.load();
    s.checkpoint = checkpoint_writer_->Stats();
    const realtime::PercentileSummary offer = checkpoint_offer_us_.Compute();
    s.checkpoint_offer_us_p50 = offer.p50;
    s.checkpoint_offer_us_p99 = offer.p99;
  }
  return s;
}

}  // namespace snapthread::server
