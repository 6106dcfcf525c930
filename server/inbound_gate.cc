#include "inbound_gate.h"

#include <utility>

#include <spdlog/spdlog.h>

#include "auth/message_gate.h"
#include "auth/message_mac.h"
#include "messages/validate.h"
#include "realtime/clock.h"

namespace snapthread::server {
namespace {

// The transports hand over LCM's uint32 sizes; anything this large is refused before
// the decoder sees it (messages::DecodeAndValidate's ReceiveBuffer overload does the same).
constexpr size_t kMaxDatagramBytes = size_t{1} << 30;

template <class Msg>
bool Decode(const void* data, size_t size, Msg* out, std::string* why) {
  if (size > kMaxDatagramBytes) {
    *why = "buffer too large";
    return false;
  }
  return messages::DecodeAndValidate(data, static_cast<int>(size), out, why);
}

}  // namespace

InboundGate::InboundGate(const messages::Channels& channels, const auth::SessionKey& key,
                         int64_t epoch, ServerInbox* inbox, ServerCounters* counters)
    : channels_(channels), key_(key), epoch_(epoch), inbox_(inbox), counters_(counters) {
  command_filter_.SetEpoch(epoch_);  // commands must carry this start's epoch
}

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

void InboundGate::AdmitDeviceState(const void* data, size_t size) {
  const std::string& channel = channels_.device_state;
  ReceivedPose sample;
  std::string why;
  if (!Decode(data, size, &sample.state, &why)) {
    CountRejection(counters_, channel, why);
    return;
  }
  // The MAC first: only a key holder's pose may create a per-device filter.
  if (!auth::VerifyEncoded(data, size, channel, key_)) {
    pose_mac_filter_.Reject(auth::Reason::kBadMac);
    RejectAuth(&pose_mac_filter_);
    return;
  }
  auth::FreshnessFilter* filter = DeviceFilter(sample.state.device_id);
  if (filter == nullptr) {
    CountRejection(counters_, channel, "more than " + std::to_string(kMaxDevices) + " devices");
    return;
  }
  if (filter->Admit(sample.state.epoch, sample.state.auth_seq) != auth::Reason::kAccepted) {
    RejectAuth(filter);
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
    CountRejection(counters_, channel, why);
    return;
  }
  if (auth::Admit(data, size, command, channel, key_, &command_filter_) !=
      auth::Reason::kAccepted) {
    RejectAuth(&command_filter_);
    return;
  }
  if (!inbox_->PushCommand(command)) {
    counters_->commands_refused.fetch_add(1);
    if (ShouldLog(&counters_->last_reject_log_us)) {
      spdlog::warn("server: command queue full, refused a command on {}", channel);
    }
  }
}

void InboundGate::RejectAuth(auth::FreshnessFilter* filter) {
  counters_->rejected_messages.fetch_add(1);
  std::string line;
  if (filter->TakeLogLine(SteadyMicros(), &line)) spdlog::warn("server: refused {}", line);
}

auth::FreshnessFilter* InboundGate::DeviceFilter(const std::string& device_id) {
  auto it = device_filters_.find(device_id);
  if (it != device_filters_.end()) return it->second.get();
  if (device_filters_.size() >= kMaxDevices) return nullptr;
  auto filter = std::make_unique<auth::FreshnessFilter>(
      "DEVICE_STATE of " + device_id, auth::FreshnessFilter::EpochPolicy::kFixed, epoch_);
  return device_filters_.emplace(device_id, std::move(filter)).first->second.get();
}

}  // namespace snapthread::server
