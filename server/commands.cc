// The COMMAND channel: RESET, LOAD_SCENE and SET_METHOD, applied on the solve thread
// between two updates. A refused command leaves the session as it was.
#include <exception>
#include <memory>
#include <string>
#include <utility>

#include <spdlog/spdlog.h>

#include "server.h"
#include "server_session.h"
#include "snapthread/force_model_t.hpp"
#include "solvers/registry.h"

namespace snapthread::server {

void Server::ApplyCommand(const command_t& command) {
  std::string message;
  bool ok = true;
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
      try {
        std::unique_ptr<Session> next = MakeSession(LoadScene(command.argument));
        session_ = std::move(next);
        message = "LOAD_SCENE: now scene '" + session_->scene.name + "' (" + command.argument + ")";
      } catch (const std::exception& e) {
        ok = false;
        message = "LOAD_SCENE refused, keeping scene '" + session_->scene.name + "': " + e.what();
      }
      break;
    }
    case command_t::SET_METHOD: {
      if (SolverRegistry::Global().Find(command.argument) == nullptr) {
        ok = false;
        message = "SET_METHOD refused: unknown method '" + command.argument + "' (expected " +
                  SolverRegistry::Global().NamesText(", ", " or ") + ")";
        break;
      }
      try {
        SolverOptions options = session_->tracker->options();
        options.method = command.argument;
        session_->tracker->SetOptions(options);
        session_->scene.solver = options;
        method_override_ = command.argument;
        message = "SET_METHOD: now " + command.argument;
      } catch (const std::exception& e) {
        ok = false;
        message = std::string("SET_METHOD failed: ") + e.what();
      }
      break;
    }
    default:
      ok = false;
      message = "unknown command " + std::to_string(command.command);
  }
  // The message first, then the counters: a caller that waits on a counter reads the
  // message of that command.
  SetInfo(session_->scene.name, session_->tracker->options().method, &message);
  if (ok) {
    // A new start: the shape's snap count is "since the session (re)started".
    if (command.command != command_t::SET_METHOD) {
      snaps_since_reset_ = 0;
      last_status_ = force_model_t::STATUS_REGULAR;
      for (double& f : last_force_n_) f = 0.0;
    }
    spdlog::info("server: {}", message);
    commands_applied_.fetch_add(1);
  } else {
    spdlog::warn("server: {}", message);
    commands_refused_.fetch_add(1);
  }
}

}  // namespace snapthread::server
