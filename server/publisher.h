// The server's way out: tags each message for its channel with this start's epoch and
// the next auth_seq (docs/security.md, "Roles on the wire") and sends it through the
// ServerTransport, counting what was published and what failed:
//  * SHAPE, SOLVER_STATUS, COMMAND_REPLY: signed by the server's key (ServerKeys::signers)
//    and, during a rotation's grace period, by the previous one too; no MAC;
//  * FORCE_MODEL: MACed with the key of the device whose pose it answers (sender_name =
//    that device), and signed only when at least kModelSignPeriodUs passed since the
//    grasp's last signed model: observers draw force arrows at display rate, and Ed25519
//    at 1 kHz would cost ~5 % of a core.
// Building a message is the solve loop's job (server_messages.h); the publisher never
// changes a message's content but its trailer.
//
// Solve thread only. Allocates nothing per message once every grasp and name was seen.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "messages/channels.h"
#include "server_keys.h"
#include "server_stats.h"
#include "server_transport.h"

namespace snapthread::server {

class Publisher {
 public:
  // The shortest time between two signed force models of one grasp (60 Hz).
  static constexpr int64_t kModelSignPeriodUs = 1000000 / 60;

  // transport, keys and counters must outlive the publisher.
  Publisher(ServerTransport* transport, const messages::Channels& channels, const ServerKeys* keys,
            int64_t epoch, ServerCounters* counters);

  // Each tags *msg and sends it; false (and a publish failure counted) when it could not
  // be tagged or the transport refused it. Published shapes and statuses are counted.
  // A force model is for grasp index `grasp` of the scene and answers a pose made with
  // `device` (nullptr: not sent, a failure).
  bool ForceModel(force_model_t* msg, int grasp, const DeviceKey* device);
  bool Shape(thread_shape_t* msg);
  bool SolverStatus(solver_status_t* msg);
  bool CommandReply(command_reply_t* msg);

 private:
  // Tags msg with `tagger` for channel and hands it to `publish` (a call of the
  // transport); false (and a publish failure counted) when it cannot be tagged or is
  // refused; else counts it in *published (when given).
  template <class Msg, class PublishFn>
  bool Send(Msg* msg, const std::string& channel, const auth::Tagger& tagger, PublishFn publish,
            std::atomic<int64_t>* published);
  // The server's signature(s) into `tagger` (current, previous in grace).
  void SetSigners(auth::Tagger* tagger) const;

  ServerTransport* transport_;
  messages::Channels channels_;
  const ServerKeys* keys_;
  int64_t epoch_;
  auth::AuthSequence auth_seq_;
  ServerCounters* counters_;
  auth::Tagger server_tagger_;  // signatures only
  auth::Tagger model_tagger_;   // a device's MAC (+ signatures at display rate)
  std::vector<int64_t> last_signed_model_us_;  // per grasp index, steady clock
};

}  // namespace snapthread::server
