// Checkpoints of the solve loop's session (--state-dir): resume at start-up, snapshots
// from the solve thread. The file format and the atomic write are in checkpoint.h, the
// writer thread in checkpoint_writer.h.
//
// Policy: a valid checkpoint of this session in --state-dir wins over --scene and
// --method: a restarted server is there to go on serving what the hand was feeling
// (scene, method, grasp, branch). Its epoch is *not* reused: every start draws a new
// one (docs/security.md); the saved epoch only names the checkpoint in the log.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "auth/session_key.h"
#include "checkpoint_writer.h"
#include "realtime/percentiles.h"
#include "server_params.h"
#include "server_stats.h"
#include "session.h"

namespace snapthread::server {

// The checkpoint at `path`, resumed: a session built with *settings (its method
// replaced by the saved one when this server may use it) on the saved branch at the
// saved grasp. nullptr when there is none or it is refused (logged with the file and the
// reason: the caller starts fresh); *settings changes only when it is resumed.
// `start_scene` (the --scene's name) and `epoch` (this start's) are for the log.
std::unique_ptr<Session> ResumeCheckpoint(const std::string& path, const auth::SessionKey& key,
                                          const ServerParams& params,
                                          const std::string& start_scene, int64_t epoch,
                                          SessionSettings* settings);

// The solve thread's side of the writer: a snapshot of the session when it changed.
class SessionCheckpoints {
 public:
  // key must outlive this. before_write: ServerTestHooks::before_checkpoint_write.
  SessionCheckpoints(const std::string& path, const auth::SessionKey& key, int64_t epoch,
                     std::function<void()> before_write);

  // Hands the writer a snapshot when the updates or applied commands changed since the
  // last one (and the state is finite); the solve thread's cost goes to info.
  void Offer(const Session& session, int64_t updates, int64_t commands, ServerInfo* info);
  // Waits until every snapshot offered is written.
  void Flush() { writer_.Flush(); }
  CheckpointWriterStats Stats() const { return writer_.Stats(); }

 private:
  CheckpointWriter writer_;
  int64_t epoch_;
  int64_t seq_ = 0;
  int64_t updates_ = -1, commands_ = -1;  // what the last snapshot saw
};

}  // namespace snapthread::server
