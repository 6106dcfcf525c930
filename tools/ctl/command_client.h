// The operator's side of the COMMAND channel (docs/security.md): learns the server's
// epoch from a SOLVER_STATUS signed by the server, sends one command tagged with the
// operator's key (its MAC) under that epoch and a fresh auth_seq, and waits for the
// server's signed COMMAND_REPLY that names this command's auth_seq. Nothing
// unauthenticated is used: a status or reply whose server signature does not verify, or
// that does not claim the server's role, is counted and ignored, and no command is sent
// before a verified status gave the epoch.
//
// One thread: every call runs LCM's handlers on the calling thread.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "auth/freshness_filter.h"
#include "auth/session_epoch.h"
#include "auth/key_set.h"
#include "messages/channels.h"
#include "snapthread/command_reply_t.hpp"
#include "snapthread/solver_status_t.hpp"

namespace snapthread::ctl {

using Clock = std::chrono::steady_clock;

// How a command ended, as the operator's console reports it.
struct CommandOutcome {
  enum class Kind {
    kApplied,   // the server applied it (reply ok)
    kRefused,   // the server refused it; message says why
    kNoServer,  // no verified SOLVER_STATUS before the deadline: nothing was sent
    kNoReply,   // sent, but no verified reply before the deadline
    kNotSent,   // the command could not be signed or published
  };
  Kind kind = Kind::kNoServer;
  std::string message;  // the server's text (as received: escape it for display)
};

class CommandClient {
 public:
  // lcm and keys (an operator's: keys.tagger() MACs) must outlive the client. Subscribes
  // to SOLVER_STATUS and COMMAND_REPLY.
  CommandClient(lcm::LCM* lcm, const messages::Channels& channels, const auth::KeySet& keys);
  ~CommandClient();
  CommandClient(const CommandClient&) = delete;
  CommandClient& operator=(const CommandClient&) = delete;

  // Waits until `deadline` for an authenticated SOLVER_STATUS newer than the last one
  // seen; true with it in *status.
  bool WaitForStatus(Clock::time_point deadline, solver_status_t* status);
  // Sends command_t `command` with `argument` and waits for its reply (see above).
  CommandOutcome Send(int8_t command, const std::string& argument, Clock::time_point deadline);

  // Statuses and replies refused (bad signature, malformed, foreign epoch), for the diagnosis
  // of a timeout: "another key?".
  uint64_t refused_statuses() const { return refused_statuses_; }
  uint64_t refused_replies() const { return refused_replies_; }

 private:
  void OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void OnReply(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  // Handles LCM messages until `done` holds (true) or the deadline passes (false).
  template <class Done>
  bool HandleUntil(Clock::time_point deadline, Done done);

  lcm::LCM* lcm_;
  messages::Channels channels_;
  const auth::KeySet& keys_;
  lcm::Subscription* status_sub_ = nullptr;
  lcm::Subscription* reply_sub_ = nullptr;
  // The server's statuses: the first verified one gives the epoch (kAdopt).
  auth::FreshnessFilter status_filter_{"SOLVER_STATUS", auth::FreshnessFilter::EpochPolicy::kAdopt};
  std::optional<solver_status_t> status_;
  int64_t statuses_seen_ = 0;
  // Starts from the wall clock: two runs in a row send increasing numbers, as the
  // server's per-session command floor requires.
  auth::AuthSequence auth_seq_;
  int64_t awaited_auth_seq_ = 0;  // 0: no command in flight
  int8_t awaited_command_ = 0;
  std::optional<command_reply_t> reply_;
  uint64_t refused_statuses_ = 0;
  uint64_t refused_replies_ = 0;
};

}  // namespace snapthread::ctl
