// The solver server (shared/DESIGN.md "architecture"): owns the thread's state, follows
// the equilibrium as device poses arrive and answers each solved pose with a local force
// model; publishes the shape for viewers and solver statistics; obeys commands.
//
// Rooms (each its own file):
//  * transport (server_transport.h): moves bytes; LCM in production
//    (lcm_server_transport.h), in memory in tests.
//  * inbound gate (inbound_gate.h): decodes, validates, authenticates and counts every
//    received datagram and hands the admitted ones to the inbox (server_inbox.h), which
//    orders them (latest pose of each grasp wins, a short FIFO of commands).
//  * solve loop (solve_loop.h) and its session (session.h: scene, tracker, snap-ahead),
//    commands (commands.cc) and checkpoints (server_checkpoint.h).
//  * publisher (publisher.h): signs and sends what the solve loop built.
//  * statistics (server_stats.h): counters every thread adds to.
// The Server below wires them and runs the two threads.
//
// Threads
//  * receive thread: transport.Receive() loop into the gate. Bad input is counted,
//    logged rate-limited and dropped; nothing there throws.
//  * solve thread: SolveLoop::Run. Waits for a new pose (latest wins), maps it to
//    controls, updates, publishes FORCE_MODEL at once, and SHAPE / SOLVER_STATUS at their
//    rates. Commands run here too, between solves.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "auth/key_file.h"
#include "auth/session_key.h"
#include "checkpoint.h"
#include "inbound_gate.h"
#include "messages/channels.h"
#include "publisher.h"
#include "server_inbox.h"
#include "server_keys.h"
#include "server_params.h"
#include "server_stats.h"
#include "server_transport.h"
#include "solve_loop.h"

namespace snapthread::server {

class Server {
 public:
  // Validates params (std::invalid_argument naming the flag), loads or creates the
  // root key (auth::KeyFileError naming the file and the fix; auth::CredentialError for a
  // role's credential, naming the root key as what the server needs), FILE.previous and
  // FILE.revoked (ServerKeys), loads the scene
  // (SceneError), prepares --state-dir (CheckpointIoError) and resets the tracker at the
  // scene's grasp_start (or resumes a checkpoint). Then opens its own LCM transport on
  // ResolveLcmUrl(params.lcm_url) (LcmInitError when it does not start).
  explicit Server(const ServerParams& params, ServerTestHooks hooks = {});
  // The same over the caller's transport, which must outlive the server.
  Server(const ServerParams& params, ServerTransport* transport, ServerTestHooks hooks = {});
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Starts the receive and solve threads. Once.
  void Start();
  // Stops and joins both threads, writes the last checkpoint. Idempotent; called by the
  // destructor.
  void Stop();
  // Asks the receive thread to reload the keys (ServerKeys::Reload: the root file, a
  // rotation, FILE.revoked) before its next receive (SIGHUP). Any thread.
  void RequestReload();
  // Reloads done since the start (a test waits for its request to be applied).
  int64_t key_reloads() const;

  ServerStats Stats() const;
  // {"updates": ..., "update_rate_hz": ..., "solve_us_p50": ..., "solve_us_p99": ...,
  //  "snaps": ..., "dropped_poses": ..., "rejected_messages": ..., ...}
  std::string SummaryJson() const;
  // One line for the end of the log: the same numbers as key=value pairs.
  std::string FinalReport() const;

  const messages::Channels& channels() const { return channels_; }
  const ServerParams& params() const { return params_; }
  // This start's session epoch (new at each construction) and the root key loaded at the
  // start (checkpoints are MACed with it).
  int64_t epoch() const { return epoch_; }
  const auth::SessionKey& key() const { return key_; }
  const auth::KeyLocation& key_location() const { return key_location_; }
  bool key_created() const { return key_created_; }

 private:
  // Makes the transport from the validated params, once the scene and checkpoints are
  // ready (a bad scene is reported before the network is touched).
  using TransportMaker = std::function<std::unique_ptr<ServerTransport>(const ServerParams&)>;
  Server(const ServerParams& params, ServerTransport* transport, TransportMaker make_transport,
         ServerTestHooks hooks);
  void ReceiveLoop();

  ServerParams params_;
  messages::Channels channels_;
  auth::KeyLocation key_location_;
  bool key_created_ = false;
  auth::SessionKey key_;
  int64_t epoch_ = 0;

  ServerCounters counters_;
  ServerInfo info_;
  ServerInbox inbox_;
  std::unique_ptr<SolveLoop> solve_loop_;
  std::unique_ptr<ServerTransport> owned_transport_;
  ServerTransport* transport_ = nullptr;
  std::unique_ptr<ServerKeys> keys_;
  std::unique_ptr<InboundGate> gate_;
  std::unique_ptr<Publisher> publisher_;

  std::thread receive_thread_, solve_thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_{false};
  std::atomic<bool> reload_requested_{false};
  bool started_ = false;
};

}  // namespace snapthread::server
