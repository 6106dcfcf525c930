#include "server_checkpoint.h"

#include <chrono>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <utility>

#include <spdlog/spdlog.h>

#include "checkpoint.h"
#include "realtime/clock.h"
#include "solvers/registry.h"

namespace snapthread::server {
namespace {

std::string Hex(int64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// The saved checkpoint as a session on its branch, or a reason (*refused) it is not.
std::unique_ptr<Session> SessionFromCheckpoint(Checkpoint* saved, const ServerParams& params,
                                               SessionSettings* settings, std::string* note,
                                               std::string* refused) {
  // The saved method when this server may use it; else the one it starts with.
  const bool method_ok = SolverRegistry::Global().Find(saved->method) != nullptr &&
                         params.IsMethodAllowed(saved->method);
  std::unique_ptr<Session> session;
  try {
    const Scene scene = ParseScene(saved->scene_text, saved->scene_file);
    if (!method_ok) {
      *note = " (its method '" + saved->method + "' is not available here)";
    } else if (saved->method != scene.solver.method || !settings->method.empty()) {
      settings->method = saved->method;
    }
    session = MakeSession(scene, *settings);
  } catch (const std::exception& e) {
    *refused = std::string("its scene does not load: ") + e.what();
    return nullptr;
  }
  const Model& model = session->tracker->model();
  const std::string model_name(model.Name());
  if (saved->x.size() != model.NumStates() || saved->u.size() != model.NumControls()) {
    *refused = "its state has " + std::to_string(saved->x.size()) + " values and its grasp " +
               std::to_string(saved->u.size()) + ", the model " + model_name + " of scene '" +
               session->scene.name + "' has " + std::to_string(model.NumStates()) + " and " +
               std::to_string(model.NumControls());
    return nullptr;
  }
  try {
    const TrackResult& result = session->tracker->Resume(saved->x, saved->u);
    if (!session->tracker->state().allFinite() || !result.force.allFinite()) {
      throw std::runtime_error("the solve from the saved state is not finite");
    }
  } catch (const std::exception& e) {
    *refused = std::string("cannot resume its state: ") + e.what();
    return nullptr;
  }
  session->scene_text = std::move(saved->scene_text);
  return session;
}

}  // namespace

std::unique_ptr<Session> ResumeCheckpoint(const std::string& path, const auth::SessionKey& key,
                                          const ServerParams& params,
                                          const std::string& start_scene, int64_t epoch,
                                          SessionSettings* settings) {
  auto refuse = [&](const std::string& reason) -> std::unique_ptr<Session> {
    spdlog::warn("server: checkpoint {} refused: {}; starting fresh at the start of scene '{}'",
                 path, reason, start_scene);
    return nullptr;
  };
  std::string bytes, reason;
  switch (ReadCheckpointFile(path, &bytes, &reason)) {
    case ReadStatus::kMissing:
      spdlog::info("server: no checkpoint {} yet; starting at the start of scene '{}'", path,
                   start_scene);
      return nullptr;
    case ReadStatus::kRefused:
      return refuse(reason);
    case ReadStatus::kOk:
      break;
  }
  Checkpoint saved;
  if (!DecodeCheckpoint(bytes, key, &saved, &reason)) return refuse(reason);
  SessionSettings trial = *settings;
  std::string method_note;
  std::unique_ptr<Session> session =
      SessionFromCheckpoint(&saved, params, &trial, &method_note, &reason);
  if (!session) return refuse(reason);
  *settings = trial;
  const double age_s = 1e-6 * static_cast<double>(realtime::RealtimeMicros() - saved.utime);
  spdlog::info("server: resumed from checkpoint of epoch {} ({}, taken {:.1f} s ago): scene '{}'{}, "
               "method {}{}, state on the saved branch (probe {:.6g}); this start's epoch is {}",
               Hex(saved.epoch), path, age_s, session->scene.name,
               session->scene.name != start_scene ? " (not --scene's '" + start_scene + "')" : "",
               session->tracker->options().method, method_note,
               session->tracker->last().probe, Hex(epoch));
  return session;
}

SessionCheckpoints::SessionCheckpoints(const std::string& path, const auth::SessionKey& key,
                                       int64_t epoch, std::function<void()> before_write)
    : writer_(path, key, std::move(before_write)), epoch_(epoch) {}

void SessionCheckpoints::Offer(const Session& session, int64_t updates, int64_t commands,
                               ServerInfo* info) {
  if (updates == updates_ && commands == commands_) return;  // unchanged
  const auto t0 = std::chrono::steady_clock::now();
  const EquilibriumTracker& tracker = *session.tracker;
  // A state that is not finite is never saved (the file would be refused anyway).
  if (!tracker.state().allFinite() || !tracker.control().allFinite()) return;
  Checkpoint c;
  c.utime = realtime::RealtimeMicros();
  c.epoch = epoch_;
  c.seq = seq_++;
  c.scene_name = session.scene.name;
  c.scene_file = session.scene.file;
  c.scene_text = session.scene_text;
  c.method = tracker.options().method;
  c.u = tracker.control();
  c.x = tracker.state();
  writer_.Offer(std::move(c));
  updates_ = updates;
  commands_ = commands;
  info->RecordCheckpointOffer(
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
}

}  // namespace snapthread::server
