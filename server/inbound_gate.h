// The server's one way in (docs/security.md): every datagram received on
// <SESSION>_DEVICE_STATE and <SESSION>_COMMAND is decoded and validated, authenticated
// (the MAC, then the freshness of its epoch and auth_seq), counted, and only then handed
// to the solve thread through the ServerInbox, which orders it (latest pose of each grasp
// wins, commands in a short FIFO). A refusal is counted in rejected_messages and logged,
// rate-limited, with its reason; a gate never throws.
//
// Receive thread only (the transport's Receive calls it).
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <string>

#include "auth/freshness_filter.h"
#include "auth/session_key.h"
#include "messages/channels.h"
#include "server_inbox.h"
#include "server_stats.h"
#include "server_transport.h"

namespace snapthread::server {

class InboundGate final : public InboundSink {
 public:
  // Devices whose freshness the server tracks; poses of further device_ids are refused
  // (a forger cannot grow the map: filters exist only after a valid MAC).
  static constexpr size_t kMaxDevices = 64;

  // Poses and commands must carry `epoch` (this start's). key, inbox and counters must
  // outlive the gate.
  InboundGate(const messages::Channels& channels, const auth::SessionKey& key, int64_t epoch,
              ServerInbox* inbox, ServerCounters* counters);

  void OnDeviceState(const void* data, size_t size) override;
  void OnCommand(const void* data, size_t size) override;

 private:
  // An authentication refusal counted by `filter`: rejected_messages + a rate-limited
  // log line with the reason.
  void RejectAuth(auth::FreshnessFilter* filter);
  // The freshness filter of one device_id, created on its first authenticated pose;
  // nullptr when kMaxDevices are known already (the pose is refused).
  auth::FreshnessFilter* DeviceFilter(const std::string& device_id);
  void AdmitDeviceState(const void* data, size_t size);
  void AdmitCommand(const void* data, size_t size);

  const messages::Channels channels_;
  const auth::SessionKey& key_;
  const int64_t epoch_;
  ServerInbox* inbox_;
  ServerCounters* counters_;
  // Refusals before a device is known (bad MAC), per-device pose freshness, commands.
  auth::FreshnessFilter pose_mac_filter_{"DEVICE_STATE"};
  std::map<std::string, std::unique_ptr<auth::FreshnessFilter>> device_filters_;
  auth::FreshnessFilter command_filter_{"COMMAND"};
};

}  // namespace snapthread::server
