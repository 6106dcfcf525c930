#include "lcm_transport.h"

#include "messages/subscribe.h"

namespace snapthread::device {

LcmDeviceTransport::LcmDeviceTransport(const std::string& url, const std::string& session)
    : lcm_(url), channels_(session) {
  if (lcm_.good()) {
    subscription_ =
        messages::Subscribe<&LcmDeviceTransport::Handle>(lcm_, channels_.force_model, this);
    status_subscription_ =
        messages::Subscribe<&LcmDeviceTransport::HandleStatus>(lcm_, channels_.solver_status, this);
  }
}

LcmDeviceTransport::~LcmDeviceTransport() {
  if (subscription_ != nullptr) lcm_.unsubscribe(subscription_);
  if (status_subscription_ != nullptr) lcm_.unsubscribe(status_subscription_);
}

void LcmDeviceTransport::HandleStatus(const lcm::ReceiveBuffer* rbuf,
                                      const std::string& /*channel*/) {
  if (rbuf == nullptr || rbuf->data_size > (1u << 20)) return;  // a status is < 1 kB
  try {
    if (statuses_.size() >= kMaxPendingStatuses) statuses_.pop_front();
    const auto* bytes = static_cast<const uint8_t*>(rbuf->data);
    statuses_.emplace_back(bytes, bytes + rbuf->data_size);
  } catch (...) {
  }
}

int LcmDeviceTransport::PollSolverStatus(const StatusSink& sink) {
  int n = 0;
  while (!statuses_.empty()) {
    const std::vector<uint8_t> bytes = std::move(statuses_.front());
    statuses_.pop_front();
    ++n;
    try {
      sink(bytes.data(), static_cast<int>(bytes.size()));
    } catch (...) {
    }
  }
  return n;
}

bool LcmDeviceTransport::PublishDeviceState(const device_state_t& msg) {
  return lcm_.publish(channels_.device_state, &msg) == 0;
}

bool LcmDeviceTransport::PublishDeviceStatus(const device_status_t& msg) {
  return lcm_.publish(channels_.device_status, &msg) == 0;
}

int LcmDeviceTransport::PollForceModels(int wait_ms, const ForceModelSink& sink) {
  if (!lcm_.good()) return -1;
  sink_ = &sink;
  delivered_ = 0;
  int rc = lcm_.handleTimeout(wait_ms);
  // More may be queued: take them without waiting again (bounded, so a flood cannot
  // keep the caller from checking its stop flag).
  for (int i = 0; rc > 0 && i < kMaxPerPoll; ++i) rc = lcm_.handleTimeout(0);
  sink_ = nullptr;
  return rc < 0 ? -1 : delivered_;
}

void LcmDeviceTransport::Handle(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
  // LCM handlers must never throw.
  if (sink_ == nullptr || rbuf == nullptr) return;
  ++delivered_;
  try {
    (*sink_)(rbuf->data, rbuf->data_size > static_cast<uint32_t>(1 << 30)
                             ? -1
                             : static_cast<int>(rbuf->data_size));
  } catch (...) {
  }
}

}  // namespace snapthread::device
