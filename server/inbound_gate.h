// The server's one way in (docs/security.md, "Roles on the wire"): every datagram
// received on <SESSION>_DEVICE_STATE and <SESSION>_COMMAND is decoded and validated, then
// authenticated by role:
//   * a pose must come from a device (sender_role), under a key the ring resolves for its
//     claimed name, expiry and key id (auth::KeyRing: unknown, expired, revoked, previous
//     root after its grace), with a MAC that verifies under it; its grasp, when named,
//     must be the device's own (the solve thread checks a pose naming no grasp against
//     the scene, solve_loop.h); then its epoch and auth_seq must be fresh for that device;
//   * a command must come from an operator, the same way.
// Only then is it handed to the solve thread through the ServerInbox (a pose with the
// device key it was made with, so the force model answering it carries that key's MAC).
// A refusal is counted in rejected_messages and per (claimed role, reason)
// (refusal_counts.h), and logged rate-limited; a gate never throws.
//
// Receive thread only (the transport's Receive calls it), like the ServerKeys it uses.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "auth/freshness_filter.h"
#include "auth/role.h"
#include "messages/channels.h"
#include "refusal_counts.h"
#include "server_inbox.h"
#include "server_keys.h"
#include "server_stats.h"
#include "server_transport.h"

namespace snapthread::server {

class InboundGate final : public InboundSink {
 public:
  // Senders (devices, operators) whose freshness the server tracks; messages of further
  // names are refused (a forger cannot grow the map: filters exist only after a valid MAC).
  static constexpr size_t kMaxSenders = 64;

  // Poses and commands must carry `epoch` (this start's). keys, inbox and counters must
  // outlive the gate.
  InboundGate(const messages::Channels& channels, ServerKeys* keys, int64_t epoch, ServerInbox* inbox,
              ServerCounters* counters);

  void OnDeviceState(const void* data, size_t size) override;
  void OnCommand(const void* data, size_t size) override;

 private:
  // Counts a refusal (rejected_messages, the role/reason table) and logs it rate-limited
  // (with `detail`, what was wrong, when given).
  void Refuse(const std::string& channel, int8_t claimed_role, std::string_view name, RefusalReason refusal,
              std::string_view detail = {});
  // The key of a message claimed by `role` (whose sender_role must be `role`) if its
  // MAC verifies under it; else refuses it and returns nullptr.
  template <class Msg>
  const auth::SessionKey* Authenticate(const void* data, size_t size, const Msg& msg,
                                       const std::string& channel, auth::Role role);
  // The freshness filter of one sender, created on its first authenticated message;
  // nullptr when kMaxSenders are known already.
  auth::FreshnessFilter* Filter(std::map<std::string, std::unique_ptr<auth::FreshnessFilter>, std::less<>>* filters,
                                const std::string& name);
  void AdmitDeviceState(const void* data, size_t size);
  void AdmitCommand(const void* data, size_t size);

  const messages::Channels channels_;
  ServerKeys* keys_;
  const int64_t epoch_;
  ServerInbox* inbox_;
  ServerCounters* counters_;
  using Filters = std::map<std::string, std::unique_ptr<auth::FreshnessFilter>, std::less<>>;
  Filters device_filters_, operator_filters_;
};

}  // namespace snapthread::server
