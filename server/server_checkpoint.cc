// Checkpoints of the Server (issue 12 item 5): resume at start-up, snapshots from the
// solve thread. The file format and the atomic write are in checkpoint.h, the writer
// thread in checkpoint_writer.h.
//
// Policy: a valid checkpoint of this session in --state-dir wins over --scene and
// --method: a restarted server is there to go on serving what the hand was feeling
// (scene, method, grasp, branch). Its epoch is *not* reused: every start draws a new
// one (docs/security.md); the saved epoch only names the checkpoint in the log.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <utility>

#include <spdlog/spdlog.h>

#include "checkpoint.h"
#include "realtime/clock.h"
#include "server.h"
#include "server_session.h"
#include "solvers/registry.h"

namespace snapthread::server {
namespace {

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string Hex(int64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

}  // namespace

void Server::SetUpCheckpoints() {
  if (params_.state_dir.empty()) return;
  PrepareStateDir(params_.state_dir);
  // The start scene's text, as LoadScene just read it, so a checkpoint reloads the same
  // scene even when the file changes later.
  session_->scene_text = ReadText(params_.scene_path);
  resumed_ = ResumeFromCheckpoint();
  checkpoint_writer_ = std::make_unique<CheckpointWriter>(
      CheckpointPath(params_.state_dir, channels_.session), key_, hooks_.before_checkpoint_write);
}

bool Server::ResumeFromCheckpoint() {
  const std::string path = CheckpointPath(params_.state_dir, channels_.session);
  auto refuse = [&](const std::string& reason) {
    spdlog::warn("server: checkpoint {} refused: {}; starting fresh at the start of scene '{}'",
                 path, reason, session_->scene.name);
    return false;
  };
  std::string bytes, reason;
  switch (ReadCheckpointFile(path, &bytes, &reason)) {
    case ReadStatus::kMissing:
      spdlog::info("server: no checkpoint {} yet; starting at the start of scene '{}'", path,
                   session_->scene.name);
      return false;
    case ReadStatus::kRefused:
      return refuse(reason);
    case ReadStatus::kOk:
      break;
  }
  Checkpoint saved;
  if (!DecodeCheckpoint(bytes, key_, &saved, &reason)) return refuse(reason);

  // The saved method when this server may use it; else the one it starts with.
  const std::string start_override = method_override_;
  std::string method_note;
  const bool method_ok = SolverRegistry::Global().Find(saved.method) != nullptr &&
                         params_.IsMethodAllowed(saved.method);
  std::unique_ptr<Session> session;
  try {
    const Scene scene = ParseScene(saved.scene_text, saved.scene_file);
    if (!method_ok) {
      method_note = " (its method '" + saved.method + "' is not available here)";
    } else if (saved.method != scene.solver.method || !method_override_.empty()) {
      method_override_ = saved.method;
    }
    session = MakeSession(scene);
  } catch (const std::exception& e) {
    method_override_ = start_override;
    return refuse(std::string("its scene does not load: ") + e.what());
  }
  const Model& model = session->tracker->model();
  const std::string model_name(model.Name());
  if (saved.x.size() != model.NumStates() || saved.u.size() != model.NumControls()) {
    method_override_ = start_override;
    return refuse("its state has " + std::to_string(saved.x.size()) + " values and its grasp " +
                  std::to_string(saved.u.size()) + ", the model " + model_name + " of scene '" +
                  session->scene.name + "' has " + std::to_string(model.NumStates()) + " and " +
                  std::to_string(model.NumControls()));
  }
  try {
    const TrackResult& result = session->tracker->Resume(saved.x, saved.u);
    if (!session->tracker->state().allFinite() || !result.force.allFinite()) {
      throw std::runtime_error("the solve from the saved state is not finite");
    }
  } catch (const std::exception& e) {
    method_override_ = start_override;
    return refuse(std::string("cannot resume its state: ") + e.what());
  }
  session->scene_text = std::move(saved.scene_text);
  const std::string start_scene = session_->scene.name;
  session_ = std::move(session);
  SetInfo(session_->scene.name, session_->tracker->options().method, nullptr);
  const double age_s = 1e-6 * static_cast<double>(realtime::RealtimeMicros() - saved.utime);
  spdlog::info("server: resumed from checkpoint of epoch {} ({}, taken {:.1f} s ago): scene '{}'{}, "
               "method {}{}, state on the saved branch (probe {:.6g}); this start's epoch is {}",
               Hex(saved.epoch), path, age_s, session_->scene.name,
               session_->scene.name != start_scene ? " (not --scene's '" + start_scene + "')" : "",
               session_->tracker->options().method, method_note,
               session_->tracker->last().probe, Hex(epoch_));
  return true;
}

void Server::OfferCheckpoint() {
  const int64_t updates = updates_.load();
  const int64_t commands = commands_applied_.load();
  if (updates == checkpoint_updates_ && commands == checkpoint_commands_) return;  // unchanged
  const auto t0 = std::chrono::steady_clock::now();
  const EquilibriumTracker& tracker = *session_->tracker;
  // A state that is not finite is never saved (the file would be refused anyway).
  if (!tracker.state().allFinite() || !tracker.control().allFinite()) return;
  Checkpoint c;
  c.utime = realtime::RealtimeMicros();
  c.epoch = epoch_;
  c.seq = checkpoint_seq_++;
  c.scene_name = session_->scene.name;
  c.scene_file = session_->scene.file;
  c.scene_text = session_->scene_text;
  c.method = tracker.options().method;
  c.u = tracker.control();
  c.x = tracker.state();
  checkpoint_writer_->Offer(std::move(c));
  checkpoint_updates_ = updates;
  checkpoint_commands_ = commands;
  const double us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
  std::lock_guard<std::mutex> lock(info_mutex_);
  checkpoint_offer_us_.Push(us);
}

}  // namespace snapthread::server
