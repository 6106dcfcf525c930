// A forger on a session's LCM group, in the test process: it holds one credential (or none)
// and tags, as well as that credential allows, what only others may send: poses for the
// device's grasp, force models answering the device's poses, commands, shapes, solver
// statuses and device statuses. Every other message is tagged as the holder honestly is
// (its own role and name, auth::KeySet::tagger()); the rest impersonate the role the
// channel needs (server for models, shapes and statuses; device "hand" for poses; an
// operator for commands) with the holder's own keys. Payloads are valid (they pass
// messages::Validate, so only the authentication can refuse them), carry the live epoch
// read off the group, and mark themselves with kForgedMarker where a field allows.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "auth/key_set.h"
#include "lcm_thread.h"
#include "messages/channels.h"

namespace snapthread::roles_test {

struct ForgerCounts {
  int64_t poses = 0, models = 0, commands = 0, shapes = 0, statuses = 0, device_statuses = 0;
};

// What a forger sends. Commands off for a holder that may send them (an operator), whose
// commands are no forgeries; only poses for a device's own stale credential.
struct ForgerPlan {
  bool poses = true;
  bool models = true;
  bool commands = true;
  bool views = true;  // shapes, solver statuses, device statuses
};

class Forger {
 public:
  // `keys` (nullptr: a forger holding nothing) must outlive the forger.
  Forger(const std::string& session, const std::string& lcm_url, const auth::KeySet* keys,
         ForgerPlan plan = {});
  ~Forger();
  Forger(const Forger&) = delete;
  Forger& operator=(const Forger&) = delete;

  // Publishes poses and models at ~200 Hz, the rest at ~20 Hz, until Stop().
  void Start();
  void Stop();
  ForgerCounts sent();
  // Genuine device poses heard (what the models answer).
  int64_t poses_heard();

 private:
  void OnDeviceState(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void Run();
  // The tagger of the i-th message: honest when i is even, else impersonating `role`
  // named `name` with the holder's keys.
  auth::Tagger TaggerFor(int64_t i, auth::Role role, const std::string& name) const;
  int64_t NextSeq();
  void PublishPose(int64_t i);
  void PublishModel(int64_t i);
  void PublishSlow(int64_t i);

  test_support::LcmThread lcm_;
  const messages::Channels channels_;
  const auth::KeySet* keys_;
  const ForgerPlan plan_;
  std::mutex mutex_;
  int64_t epoch_ = 0;
  int64_t pose_seq_ = 0, pose_utime_ = 0, poses_heard_ = 0;
  double position_[3] = {0.0, 0.0, 0.0};
  ForgerCounts sent_;
  int64_t seq_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace snapthread::roles_test
