// The solve thread (server.h "Threads"): owns the session (session.h) and everything
// that changes it. Waits on the inbox for poses (latest wins) and commands, solves,
// answers each solved pose with its grasp's force model at once, and publishes SHAPE and
// SOLVER_STATUS at their rates; applies commands between two updates (commands.cc) and
// hands checkpoints to their writer (server_checkpoint.h).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "auth/session_key.h"
#include "background_job.h"
#include "knot_watch.h"
#include "messages/channels.h"
#include "publisher.h"
#include "realtime/percentiles.h"
#include "server_checkpoint.h"
#include "server_inbox.h"
#include "server_params.h"
#include "server_stats.h"
#include "session.h"
#include "snapthread/command_t.hpp"

namespace snapthread::server {

// Test seams. Called on the solve thread unless said otherwise.
struct ServerTestHooks {
  // Just before each tracker update (a test blocks here to pile up poses).
  std::function<void()> before_update;
  // On the loader thread, before a LOAD_SCENE reads its file (a test makes loads slow).
  std::function<void()> before_load;
  // Just after each tracker update, with the controls and the tracker (its state and
  // last result): a test compares the server's path with a sweep of the same scene.
  std::function<void(const Vec& u, const EquilibriumTracker& tracker)> after_update;
  // On the checkpoint writer thread, before each write (a test blocks it: a slow disk).
  std::function<void()> before_checkpoint_write;
};

// Which command a reply answers: its code and its sender's auth_seq.
struct CommandId {
  int8_t command = 0;
  int64_t auth_seq = 0;
};

class SolveLoop {
 public:
  // Loads the start scene (SceneError), prepares --state-dir (CheckpointIoError) and
  // resumes a valid checkpoint of this session (a refused one is logged and the loop
  // starts fresh). params must be valid; key, counters and info must outlive the loop.
  SolveLoop(const ServerParams& params, const messages::Channels& channels,
            const auth::SessionKey& key, int64_t epoch, ServerTestHooks hooks,
            ServerCounters* counters, ServerInfo* info);
  SolveLoop(const SolveLoop&) = delete;
  SolveLoop& operator=(const SolveLoop&) = delete;

  // The solve thread: until the inbox is stopped. Publishes through *publisher.
  void Run(ServerInbox* inbox, Publisher* publisher);
  // After Run: the last checkpoint (so a restart resumes exactly here), and a scene load
  // still running joined.
  void Finish();

  // "scene 'name' (file), method m" for the start-up log line. Not while Run runs.
  std::string Describe() const;
  // resumed, the writer's figures; nothing without --state-dir.
  void CopyCheckpointStats(ServerStats* s) const;

 private:
  SessionSettings Settings() const;
  // Drops (and counts as wrong-grasp) poses naming no grasp whose device is not the one
  // of the grasp such a pose drives.
  void RefuseForeignGrasps(std::vector<ReceivedPose>* poses);
  void SolveAndPublish(const std::vector<ReceivedPose>& poses);
  // The force model of one grasp for the pose that moved it (its block of F and K).
  void PublishGraspModel(const ReceivedPose& pose, int grasp, const SessionUpdate& update,
                         bool first);
  void PublishShape();
  void PublishStatus();
  void OfferCheckpoint();
  void SetInfo(const std::string* command);

  // Commands (commands.cc).
  void ApplyCommand(const command_t& command);
  bool SetMethod(const std::string& method, std::string* message, bool* rejected);
  // LOAD_SCENE off the solve thread: starts the loader; Run polls it and swaps the
  // session in when it is ready (true when the session changed or a load ended).
  void StartSceneLoad(const command_t& command);
  bool PollSceneLoad();
  // Logs and counts the outcome of `command` (its code and auth_seq) and answers it on
  // COMMAND_REPLY; `rejected` also counts a policy refusal in rejected_messages.
  void FinishCommand(const CommandId& command, bool ok, const std::string& message,
                     bool rejected = false);
  void PublishReply(const CommandId& command, bool ok, const std::string& message);

  ServerParams params_;
  messages::Channels channels_;
  ServerTestHooks hooks_;
  ServerCounters* counters_;
  ServerInfo* info_;
  Publisher* publisher_ = nullptr;  // during Run

  std::unique_ptr<Session> session_;
  std::string method_override_;  // "" = the scene's
  BackgroundJob<Session> load_;   // the LOAD_SCENE in progress, if any
  std::string load_name_;         // its argument
  CommandId load_command_;        // answered when the load ends
  KnotWatch knot_watch_;          // the shape's knot type, a few times a second
  std::unique_ptr<SessionCheckpoints> checkpoints_;  // null without --state-dir
  bool resumed_ = false;          // this start resumed a checkpoint

  // What the shape and status report.
  int64_t model_seq_ = 0, shape_seq_ = 0, status_seq_ = 0, reply_seq_ = 0;
  int64_t snaps_since_reset_ = 0;
  int8_t last_status_ = 0;
  std::array<double, 3> last_force_n_{0.0, 0.0, 0.0};
  realtime::SampleWindow status_window_{4096};  // solve µs since the last status
  int64_t updates_at_last_status_ = 0;
  std::chrono::steady_clock::time_point last_status_time_;
};

}  // namespace snapthread::server
