// What the server counts and reports (Server::Stats, the solver status, the summary):
// the counters every thread adds to, and the few figures that need a lock.
//
// The receive thread (the inbound gate) and the solve thread both count rejected
// messages and refused commands, so the counters live here rather than in either room.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

#include "checkpoint_writer.h"
#include "realtime/percentiles.h"
#include "refusal_counts.h"

namespace snapthread::server {

// Counters since construction; each field is read atomically (the set is not a single
// snapshot, which statistics do not need).
struct ServerStats {
  int64_t poses_received = 0;     // valid device states
  int64_t updates = 0;            // equilibrium updates answered with a force model
  int64_t invalid_models = 0;     // of those, STATUS_INVALID (failed solve)
  int64_t snaps = 0;              // updates that snapped
  int64_t dropped_poses = 0;      // poses superseded before the solver took them
  int64_t rejected_messages = 0;  // malformed / invalid DEVICE_STATE or COMMAND packets
  std::string refusals;           // per claimed role and reason (RefusalCounts::Format)
  int64_t commands_applied = 0;
  int64_t commands_refused = 0;   // bad scene, unknown method, queue full
  int64_t shapes_published = 0;
  int64_t statuses_published = 0;
  int64_t publish_failures = 0;
  double update_rate_hz = 0.0;    // updates / time between the first and last update
  double solve_us_p50 = 0.0;      // over the last ServerInfo::kSolveWindow updates
  double solve_us_p99 = 0.0;
  std::string scene;              // name of the scene in use
  std::string method;             // solver method in use
  std::string last_command_message;  // what the last command did or why it was refused
  // Checkpoints (--state-dir; server_checkpoint.cc). All zero / false without it.
  bool checkpoints = false;          // --state-dir given
  bool resumed = false;              // this start resumed a checkpoint
  CheckpointWriterStats checkpoint;  // files written, failures, write time
  double checkpoint_offer_us_p50 = 0.0;  // the solve thread's cost of one snapshot
  double checkpoint_offer_us_p99 = 0.0;
};

// The counters of ServerStats, added to from any thread, and the rate limits of the
// warnings they go with.
struct ServerCounters {
  std::atomic<int64_t> poses_received{0}, updates{0}, invalid_models{0}, snaps{0},
      dropped_poses{0}, rejected_messages{0}, commands_applied{0}, commands_refused{0},
      shapes_published{0}, statuses_published{0}, publish_failures{0};
  // Refused DEVICE_STATE and COMMAND messages by claimed role and reason (each also in
  // rejected_messages).
  RefusalCounts refusals;
  // Last log time (steady µs) of a "bad message" warning and of a solve-thread error.
  std::atomic<int64_t> last_reject_log_us{0};
  std::atomic<int64_t> last_solve_error_log_us{0};

  // The counters into *s (the fields above update_rate_hz, and refusals).
  void CopyTo(ServerStats* s) const;
};

// Steady clock, microseconds.
int64_t SteadyMicros();
// True at most once per second per *last (any thread).
bool ShouldLog(std::atomic<int64_t>* last);
// Counts a bad message in rejected_messages and says why, at most once per second.
void CountRejection(ServerCounters* counters, const std::string& channel, const std::string& why);

// The figures of ServerStats that need a lock: names in use, the last command's message,
// solve times and the checkpoint snapshot cost. Any thread.
class ServerInfo {
 public:
  static constexpr size_t kSolveWindow = 100000;

  // The scene and method in use and, when command != nullptr, the last command's message.
  void Set(const std::string& scene, const std::string& method, const std::string* command);
  // One update's solve time (and the time of the first and last update).
  void RecordSolve(double solve_us);
  void RecordCheckpointOffer(double us);
  // Names, solve percentiles, the update rate from s->updates, and with
  // `checkpoints` the snapshot cost.
  void CopyTo(ServerStats* s, bool checkpoints) const;

 private:
  mutable std::mutex mutex_;
  std::string scene_name_, method_name_, last_command_message_;
  realtime::SampleWindow run_window_{kSolveWindow};
  int64_t first_update_us_ = 0, last_update_us_ = 0;  // steady clock
  realtime::SampleWindow checkpoint_offer_us_{4096};
};

}  // namespace snapthread::server
