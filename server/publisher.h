// The server's way out: signs each message for its channel with this start's epoch and
// the next auth_seq (docs/security.md) and sends it through the ServerTransport,
// counting what was published and what failed. Building a message is the solve loop's
// job (server_messages.h); the publisher never changes a message's content but its
// epoch, auth_seq and mac.
//
// Solve thread only.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "auth/session_key.h"
#include "messages/channels.h"
#include "server_stats.h"
#include "server_transport.h"

namespace snapthread::server {

class Publisher {
 public:
  // transport, key and counters must outlive the publisher.
  Publisher(ServerTransport* transport, const messages::Channels& channels,
            const auth::SessionKey& key, int64_t epoch, ServerCounters* counters);

  // Each signs *msg and sends it; false (and a publish failure counted) when it could not
  // be signed or the transport refused it. Published shapes and statuses are counted.
  bool ForceModel(force_model_t* msg);
  bool Shape(thread_shape_t* msg);
  bool SolverStatus(solver_status_t* msg);
  bool CommandReply(command_reply_t* msg);

 private:
  // Signs msg for channel and hands it to `publish` (a call of the transport); false (and
  // a publish failure counted) when it cannot be signed or is refused; else counts it in
  // *published (when given).
  template <class Msg, class PublishFn>
  bool Send(Msg* msg, const std::string& channel, PublishFn publish,
            std::atomic<int64_t>* published);

  ServerTransport* transport_;
  messages::Channels channels_;
  const auth::SessionKey& key_;
  int64_t epoch_;
  auth::AuthSequence auth_seq_;
  ServerCounters* counters_;
};

}  // namespace snapthread::server
