// The COMMAND channel: RESET, LOAD_SCENE and SET_METHOD, applied on the solve thread
// between two updates. A refused command leaves the session as it was.
//
// Commands come from the network: LOAD_SCENE takes a scene *name* from
// --scene-dir (scene_dir.h) and loads it on a loader thread with a time limit, so the
// solve thread keeps serving the current scene; SET_METHOD is limited to --allow-methods.
#include <algorithm>
#include <chrono>
#include <exception>
#include <memory>
#include <string>
#include <utility>

#include <spdlog/spdlog.h>

#include "messages/validate.h"
#include "realtime/clock.h"
#include "scene_dir.h"
#include "solve_loop.h"
#include "snapthread/force_model_t.hpp"
#include "solvers/registry.h"

namespace snapthread::server {

void SolveLoop::ApplyCommand(const command_t& command) {
  std::string message;
  bool ok = true;
  bool rejected = false;
  switch (command.command) {
    case command_t::RESET: {
      try {
        session_->tracker->Reset(session_->scene.grasp_start);
        message = "RESET: back to the start of scene '" + session_->scene.name + "'";
      } catch (const std::exception& e) {
        ok = false;
        message = std::string("RESET failed: ") + e.what();
      }
      break;
    }
    case command_t::LOAD_SCENE: {
      // A name that is not one (a path, "..") is refused here at once; the file itself is
      // opened and checked on the loader thread.
      try {
        SceneFileName(command.argument);
      } catch (const SceneNameError& e) {
        ok = false;
        rejected = true;
        message = std::string(e.what()) + "; keeping scene '" + session_->scene.name + "'";
        break;
      }
      if (load_.busy()) {
        ok = false;
        message = "LOAD_SCENE '" + command.argument + "' refused: LOAD_SCENE '" + load_name_ +
                  "' is still in progress";
        break;
      }
      StartSceneLoad(command);
      return;  // reported when the load ends (PollSceneLoad)
    }
    case command_t::SET_METHOD:
      ok = SetMethod(command.argument, &message, &rejected);
      break;
    default:
      ok = false;
      message = "unknown command " + std::to_string(command.command);
  }
  FinishCommand({command.command, command.auth_seq}, ok, message, rejected);
}

bool SolveLoop::SetMethod(const std::string& method, std::string* message, bool* rejected) {
  if (SolverRegistry::Global().Find(method) == nullptr) {
    *message = "SET_METHOD refused: unknown method '" + method + "' (expected " +
               SolverRegistry::Global().NamesText(", ", " or ") + ")";
    return false;
  }
  if (!params_.IsMethodAllowed(method)) {
    *rejected = true;
    *message = "SET_METHOD refused: method '" + method +
               "' is not in --allow-methods; keeping " + session_->tracker->options().method;
    return false;
  }
  // The loader builds the next session with method_override_: keep it fixed meanwhile.
  if (load_.busy()) {
    *message = "SET_METHOD refused: LOAD_SCENE '" + load_name_ + "' is in progress, retry";
    return false;
  }
  try {
    SolverOptions options = session_->tracker->options();
    options.method = method;
    session_->tracker->SetOptions(options);
    session_->scene.solver = options;
    method_override_ = method;
    *message = "SET_METHOD: now " + method;
  } catch (const std::exception& e) {
    *message = std::string("SET_METHOD failed: ") + e.what();
    return false;
  }
  return true;
}

void SolveLoop::StartSceneLoad(const command_t& command) {
  const std::string& name = command.argument;
  load_name_ = name;
  load_command_ = {command.command, command.auth_seq};
  const std::string dir = params_.scene_dir;
  const auto limit = std::chrono::duration_cast<BackgroundJob<Session>::Clock::duration>(
      std::chrono::duration<double>(params_.load_timeout_s));
  spdlog::info("server: LOAD_SCENE '{}': loading from {}", name, dir);
  // The loader reads hooks_ and the settings (fixed while it runs: SET_METHOD waits) and
  // builds a new session; it never touches session_.
  load_.Start(
      [this, dir, name, settings = Settings()]() -> std::unique_ptr<Session> {
        if (hooks_.before_load) hooks_.before_load();
        std::string path;
        const std::string text = ReadSceneByName(dir, name, &path);
        std::unique_ptr<Session> session = MakeSession(ParseScene(text, path), settings);
        session->scene_text = text;  // for checkpoints
        return session;
      },
      limit);
}

bool SolveLoop::PollSceneLoad() {
  std::unique_ptr<Session> next;
  BackgroundJob<Session>::Failure failure;
  const std::string keeping = "keeping scene '" + session_->scene.name + "'";
  switch (load_.Poll(&next, &failure)) {
    case BackgroundJob<Session>::State::kIdle:
    case BackgroundJob<Session>::State::kRunning:
      return false;
    case BackgroundJob<Session>::State::kDone:
      session_ = std::move(next);
      FinishCommand(load_command_, true,
                    "LOAD_SCENE: now scene '" + session_->scene.name + "' (" + load_name_ + ")");
      return true;
    case BackgroundJob<Session>::State::kFailed: {
      bool policy = false;
      try {
        if (failure.error) std::rethrow_exception(failure.error);
      } catch (const SceneNameError&) {
        policy = true;
      } catch (...) {
      }
      FinishCommand(load_command_, false,
                    "LOAD_SCENE refused, " + keeping + ": " + failure.message, policy);
      return true;
    }
    case BackgroundJob<Session>::State::kTimedOut:
      FinishCommand(load_command_, false,
                    "LOAD_SCENE '" + load_name_ + "' abandoned after " +
                        std::to_string(params_.load_timeout_s) + " s (--load-timeout), " + keeping,
                    true);
      return true;
  }
  return false;
}

void SolveLoop::FinishCommand(const CommandId& command, bool ok, const std::string& message,
                              bool rejected) {
  // The message first, then the counters: a caller that waits on a counter reads the
  // message of that command.
  SetInfo(&message);
  if (ok) {
    // A new start: the shape's snap count is "since the session (re)started".
    if (command.command != command_t::SET_METHOD) {
      snaps_since_reset_ = 0;
      last_status_ = force_model_t::STATUS_REGULAR;
      last_force_n_ = {0.0, 0.0, 0.0};
    }
    spdlog::info("server: {}", message);
    counters_->commands_applied.fetch_add(1);
  } else {
    spdlog::warn("server: {}", message);
    if (rejected) counters_->rejected_messages.fetch_add(1);
    counters_->commands_refused.fetch_add(1);
  }
  PublishReply(command, ok, message);
}

void SolveLoop::PublishReply(const CommandId& command, bool ok, const std::string& message) {
  if (publisher_ == nullptr) return;  // not running: nobody waits for an answer
  command_reply_t reply;
  reply.utime = realtime::RealtimeMicros();
  reply.seq = ++reply_seq_;
  reply.command_auth_seq = command.auth_seq;
  reply.command = command.command;
  reply.ok = ok ? 1 : 0;
  // The server's own text, cut to what a reply may carry (a scene error can be long).
  reply.message = message.substr(0, messages::kMaxCommandReplyBytes);
  std::replace(reply.message.begin(), reply.message.end(), '\0', '?');  // LCM strings end at a NUL
  publisher_->CommandReply(&reply);
}

}  // namespace snapthread::server
