#include "inbound_gate.h"

#include <utility>

#include <spdlog/spdlog.h>

#include "auth/message_mac.h"
#include "messages/validate.h"
#include "realtime/clock.h"

namespace snapthread::server {
namespace {

// The transports hand over LCM's uint32 sizes; anything this large is refused before
// the decoder sees it (messages::DecodeAndValidate's ReceiveBuffer overload does the same).
constexpr size_t kMaxDatagramBytes = size_t{1} << 30;
constexpr int8_t kUnknownRole = -1;  // not decoded: counted as "unknown"

template <class Msg>
bool Decode(const void* data, size_t size, Msg* out, std::string* why) {
  if (size > kMaxDatagramBytes) {
    *why = "buffer too large";
    return false;
  }
  return messages::DecodeAndValidate(data, static_cast<int>(size), out, why);
}

}  // namespace

InboundGate::InboundGate(const messages::Channels& channels, ServerKeys* keys, int64_t epoch,
                         ServerInbox* inbox, ServerCounters* counters)
    : channels_(channels), keys_(keys), epoch_(epoch), inbox_(inbox), counters_(counters) {}

void InboundGate::OnDeviceState(const void* data, size_t size) {
  try {
    AdmitDeviceState(data, size);
  } catch (...) {
    // Only allocation can throw here; a receive handler must not let it escape.
    counters_->rejected_messages.fetch_add(1);
  }
}

void InboundGate::OnCommand(const void* data, size_t size) {
  try {
    AdmitCommand(data, size);
  } catch (...) {
    counters_->rejected_messages.fetch_add(1);
  }
}

void InboundGate::Refuse(const std::string& channel, int8_t claimed_role, std::string_view name,
                         RefusalReason refusal, std::string_view detail) {
  counters_->refusals.Count(claimed_role, refusal);
  const int64_t total = counters_->rejected_messages.fetch_add(1) + 1;
  if (ShouldLog(&counters_->last_reject_log_us)) {
    const std::string_view role =
        claimed_role >= 0 && claimed_role <= static_cast<int8_t>(auth::Role::kOperator)
            ? auth::RoleToString(static_cast<auth::Role>(claimed_role))
            : std::string_view("unknown");
    spdlog::warn("server: refused a message on {} from {} '{}': {}{}{} ({} refused since start: {})", channel,
                 role, name, RefusalName(refusal), detail.empty() ? "" : ": ", detail, total,
                 counters_->refusals.Format());
  }
}

template <class Msg>
const auth::SessionKey* InboundGate::Authenticate(const void* data, size_t size, const Msg& msg,
                                                  const std::string& channel, auth::Role role) {
  if (msg.sender_role != static_cast<int8_t>(role)) {
    Refuse(channel, msg.sender_role, msg.sender_name, RefusalReason::kWrongRole);
    return nullptr;
  }
  const auth::ResolvedKey resolved = keys_->Resolve(role, msg.sender_name, msg.key_expires,
                                                    auth::KeyIdFromWire(msg.key_id), UnixSeconds());
  if (resolved.verdict != auth::KeyVerdict::kAccepted || resolved.key == nullptr) {
    Refuse(channel, msg.sender_role, msg.sender_name, RefusalOf(resolved.verdict));
    return nullptr;
  }
  if (!auth::VerifyMac(data, size, channel, *resolved.key)) {
    Refuse(channel, msg.sender_role, msg.sender_name, RefusalReason::kBadMac);
    return nullptr;
  }
  return resolved.key;
}

void InboundGate::AdmitDeviceState(const void* data, size_t size) {
  const std::string& channel = channels_.device_state;
  ReceivedPose sample;
  std::string why;
  if (!Decode(data, size, &sample.state, &why)) {
    Refuse(channel, kUnknownRole, "", RefusalReason::kMalformed, why);
    return;
  }
  const device_state_t& s = sample.state;
  const auth::SessionKey* key = Authenticate(data, size, s, channel, auth::Role::kDevice);
  if (key == nullptr) return;
  // A device drives only its own grasp (a pose naming none is checked by the solve
  // thread, which knows the scene's grasps).
  if (!s.grasp.empty() && s.grasp != s.sender_name) {
    Refuse(channel, s.sender_role, s.sender_name, RefusalReason::kWrongGrasp);
    return;
  }
  auth::FreshnessFilter* filter = Filter(&device_filters_, s.sender_name);
  sample.key = filter != nullptr ? keys_->DeviceKeyFor(s.sender_name, s.key_expires,
                                                       auth::KeyIdFromWire(s.key_id), *key)
                                 : nullptr;
  if (sample.key == nullptr) {
    Refuse(channel, s.sender_role, s.sender_name, RefusalReason::kTooMany);
    return;
  }
  if (const auth::Reason fresh = filter->Admit(s.epoch, s.auth_seq); fresh != auth::Reason::kAccepted) {
    Refuse(channel, s.sender_role, s.sender_name, RefusalOf(fresh));
    return;
  }
  sample.receive_utime = realtime::RealtimeMicros();
  counters_->poses_received.fetch_add(1);
  if (inbox_->PutPose(sample)) counters_->dropped_poses.fetch_add(1);
}

void InboundGate::AdmitCommand(const void* data, size_t size) {
  const std::string& channel = channels_.command;
  command_t command;
  std::string why;
  if (!Decode(data, size, &command, &why)) {
    Refuse(channel, kUnknownRole, "", RefusalReason::kMalformed, why);
    return;
  }
  if (Authenticate(data, size, command, channel, auth::Role::kOperator) == nullptr) return;
  auth::FreshnessFilter* filter = Filter(&operator_filters_, command.sender_name);
  if (filter == nullptr) {
    Refuse(channel, command.sender_role, command.sender_name, RefusalReason::kTooMany);
    return;
  }
  if (const auth::Reason fresh = filter->Admit(command.epoch, command.auth_seq);
      fresh != auth::Reason::kAccepted) {
    Refuse(channel, command.sender_role, command.sender_name, RefusalOf(fresh));
    return;
  }
  if (!inbox_->PushCommand(command)) {
    counters_->commands_refused.fetch_add(1);
    if (ShouldLog(&counters_->last_reject_log_us)) {
      spdlog::warn("server: command queue full, refused a command on {}", channel);
    }
  }
}

auth::FreshnessFilter* InboundGate::Filter(Filters* filters, const std::string& name) {
  auto it = filters->find(name);
  if (it != filters->end()) return it->second.get();
  if (filters->size() >= kMaxSenders) return nullptr;
  auto filter = std::make_unique<auth::FreshnessFilter>(name, auth::FreshnessFilter::EpochPolicy::kFixed, epoch_);
  return filters->emplace(name, std::move(filter)).first->second.get();
}

}  // namespace snapthread::server
