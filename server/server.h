// The solver server (shared/DESIGN.md "architecture"): owns the thread's state, follows
// the equilibrium as device poses arrive and answers each solved pose with a local force
// model; publishes the shape for viewers and solver statistics; obeys commands.
//
// Threads
//  * receive thread: lcm.handleTimeout() loop. The handlers only decode + validate
//    (bad input is counted, logged rate-limited and dropped; handlers never throw) and
//    hand the pose / command to the solve thread through a ServerInbox.
//  * solve thread: owns the scene and the EquilibriumTracker. Waits for a new pose
//    (latest wins), maps it to controls, updates, publishes FORCE_MODEL at once, and
//    SHAPE / SOLVER_STATUS at their rates. Commands run here too, between solves.
//
// Tests replace the transport by passing their own lcm::LCM (memq:// in one process);
// the server then spins that instance's handle loop in its receive thread, so the test's
// own subscriptions on it are dispatched there as well.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include "auth/freshness_filter.h"
#include "auth/key_file.h"
#include "auth/session_epoch.h"
#include "auth/session_key.h"

#include "background_job.h"
#include "checkpoint_writer.h"
#include "knot_watch.h"
#include "server_inbox.h"
#include "server_params.h"
#include "scene/scene.h"
#include "tracking/tracker.h"
#include "messages/channels.h"
#include "realtime/percentiles.h"

namespace snapthread::server {

// LCM could not start on the URL (exit code 1 in snapthread-server).
class LcmInitError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Counters since construction; each field is read atomically (the set is not a single
// snapshot, which statistics do not need).
struct ServerStats {
  int64_t poses_received = 0;     // valid device states
  int64_t updates = 0;            // equilibrium updates answered with a force model
  int64_t invalid_models = 0;     // of those, STATUS_INVALID (failed solve)
  int64_t snaps = 0;              // updates that snapped
  int64_t dropped_poses = 0;      // poses superseded before the solver took them
  int64_t rejected_messages = 0;  // malformed / invalid DEVICE_STATE or COMMAND packets
  int64_t commands_applied = 0;
  int64_t commands_refused = 0;   // bad scene, unknown method, queue full
  int64_t shapes_published = 0;
  int64_t statuses_published = 0;
  int64_t publish_failures = 0;
  double update_rate_hz = 0.0;    // updates / time between the first and last update
  double solve_us_p50 = 0.0;      // over the last kSolveWindow updates
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

// Test seams. Called on the solve thread.
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

class Server {
 public:
  static constexpr size_t kSolveWindow = 100000;

  // Validates params (std::invalid_argument naming the flag), loads or creates the
  // session key (auth::KeyFileError naming the file and the fix), loads the scene
  // (SceneError) and resets the tracker at the scene's grasp_start. With lcm == nullptr
  // the server creates its own LCM on ResolveLcmUrl(params.lcm_url) (LcmInitError when
  // it does not start); otherwise it uses *lcm, which must outlive the server.
  explicit Server(const ServerParams& params, lcm::LCM* lcm = nullptr,
                  ServerTestHooks hooks = {});
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Subscribes and starts the receive and solve threads. Once.
  void Start();
  // Stops and joins both threads, unsubscribes. Idempotent; called by the destructor.
  void Stop();

  ServerStats Stats() const;
  // {"updates": ..., "update_rate_hz": ..., "solve_us_p50": ..., "solve_us_p99": ...,
  //  "snaps": ..., "dropped_poses": ..., "rejected_messages": ..., ...}
  std::string SummaryJson() const;
  // One line for the end of the log: the same numbers as key=value pairs.
  std::string FinalReport() const;

  const messages::Channels& channels() const { return channels_; }
  const std::string& lcm_url() const { return lcm_url_; }
  const ServerParams& params() const { return params_; }
  // This start's session epoch (new at each construction) and the key in use.
  int64_t epoch() const { return epoch_; }
  const auth::SessionKey& key() const { return key_; }
  const auth::KeyLocation& key_location() const { return key_location_; }
  bool key_created() const { return key_created_; }

 private:
  struct Session;  // scene + tracker, owned by the solve thread

  // LCM handlers (receive thread). Never throw.
  void HandleDeviceState(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void HandleCommand(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void Reject(const std::string& channel, const std::string& why);
  // An authentication refusal counted by `filter`: rejected_messages + a rate-limited
  // log line with the reason.
  void RejectAuth(auth::FreshnessFilter* filter);
  // The freshness filter of one device_id, created on its first authenticated pose;
  // nullptr when kMaxDevices are known already (the pose is refused).
  auth::FreshnessFilter* DeviceFilter(const std::string& device_id);
  // Signs msg for channel with this session's epoch and the next auth_seq; false (and
  // a publish failure counted) when it cannot be signed.
  template <class Msg>
  bool SignForChannel(Msg* msg, const std::string& channel);

  void ReceiveLoop();
  void SolveLoop();
  // Solve thread.
  void SolveAndPublish(const std::vector<ReceivedPose>& poses);
  // The force model of one grasp for the pose that moved it (its block of F and K).
  void PublishGraspModel(const ReceivedPose& pose, int grasp, const Vec& u, const TrackResult* result,
                         double solve_us, bool first);
  void ApplyCommand(const command_t& command);
  // LOAD_SCENE off the solve thread (commands.cc): starts the loader; the solve loop polls
  // it and swaps the session in when it is ready (true when the session changed or a
  // load ended).
  void StartSceneLoad(const std::string& name);
  bool PollSceneLoad();
  // Logs and counts the outcome of a command; `rejected` also counts a policy refusal in
  // rejected_messages.
  void FinishCommand(int8_t command, bool ok, const std::string& message, bool rejected = false);
  void PublishShape();
  void PublishStatus();
  std::unique_ptr<Session> MakeSession(const Scene& scene) const;
  // Checkpoints (server_checkpoint.cc). At construction: prepares --state-dir
  // (CheckpointIoError), resumes a valid checkpoint of this session (a refused one is
  // logged with its reason and the server starts fresh) and starts the writer.
  void SetUpCheckpoints();
  bool ResumeFromCheckpoint();
  // Solve thread: hands the writer a snapshot when the state changed since the last one.
  void OfferCheckpoint();
  void SetInfo(const std::string& scene, const std::string& method, const std::string* command);

  // Devices whose freshness the server tracks; poses of further device_ids are refused
  // (a forger cannot grow the map: filters exist only after a valid MAC).
  static constexpr size_t kMaxDevices = 64;

  ServerParams params_;
  messages::Channels channels_;
  auth::KeyLocation key_location_;
  bool key_created_ = false;
  auth::SessionKey key_;
  int64_t epoch_ = 0;
  auth::AuthSequence auth_seq_;
  // Receive thread: refusals before a device is known (bad MAC), per-device pose
  // freshness, commands.
  auth::FreshnessFilter pose_mac_filter_{"DEVICE_STATE"};
  std::map<std::string, std::unique_ptr<auth::FreshnessFilter>> device_filters_;
  auth::FreshnessFilter command_filter_{"COMMAND"};
  std::string lcm_url_;
  std::unique_ptr<lcm::LCM> owned_lcm_;
  lcm::LCM* lcm_ = nullptr;
  ServerTestHooks hooks_;
  lcm::Subscription* state_sub_ = nullptr;
  lcm::Subscription* command_sub_ = nullptr;

  ServerInbox inbox_;
  std::thread receive_thread_, solve_thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_{false};
  bool started_ = false;

  // Solve-thread state.
  std::unique_ptr<Session> session_;
  std::string method_override_;  // "" = the scene's method
  BackgroundJob<Session> load_;   // the LOAD_SCENE in progress, if any
  KnotWatch knot_watch_;          // the shape's knot type, a few times a second
  std::string load_name_;         // its argument
  int64_t model_seq_ = 0, shape_seq_ = 0, status_seq_ = 0;
  int64_t snaps_since_reset_ = 0;
  bool switched_ = false;  // this update started on the branch a snap-ahead switch chose
  int8_t last_status_ = 0;
  double last_force_n_[3] = {0.0, 0.0, 0.0};
  realtime::SampleWindow status_window_{4096};  // solve µs since the last status
  int64_t updates_at_last_status_ = 0;
  std::chrono::steady_clock::time_point last_status_time_;

  // Shared counters.
  std::atomic<int64_t> poses_received_{0}, updates_{0}, invalid_models_{0}, snaps_{0},
      dropped_poses_{0}, rejected_messages_{0}, commands_applied_{0}, commands_refused_{0},
      shapes_published_{0}, statuses_published_{0}, publish_failures_{0};
  std::atomic<int64_t> last_reject_log_us_{0};
  std::atomic<int64_t> last_solve_error_log_us_{0};
  mutable std::mutex info_mutex_;  // guards the fields below
  std::string scene_name_, method_name_, last_command_message_;
  realtime::SampleWindow run_window_{kSolveWindow};
  int64_t first_update_us_ = 0, last_update_us_ = 0;  // steady clock

  // Checkpoints: the writer (null without --state-dir), and on the solve thread what the
  // last snapshot saw (updates and applied commands), its count and its cost.
  std::unique_ptr<CheckpointWriter> checkpoint_writer_;
  std::atomic<bool> resumed_{false};
  int64_t checkpoint_seq_ = 0;
  int64_t checkpoint_updates_ = -1, checkpoint_commands_ = -1;
  realtime::SampleWindow checkpoint_offer_us_{4096};  // guarded by info_mutex_
};

}  // namespace snapthread::server
