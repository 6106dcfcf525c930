#include "lcm_transport.h"

#include <cstring>

#include "messages/subscribe.h"
#include "messages/publish.h"

namespace snapthread::device {

LcmDeviceTransport::LcmDeviceTransport(const std::string& url, const std::string& session)
    : lcm_(url), channels_(session), status_slot_(kMaxStatusBytes) {
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
  if (rbuf == nullptr) return;
  if (rbuf->data_size > kMaxStatusBytes) {
    statuses_oversized_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (status_pending_) statuses_superseded_.fetch_add(1, std::memory_order_relaxed);
  std::memcpy(status_slot_.data(), rbuf->data, rbuf->data_size);
  status_size_ = rbuf->data_size;
  status_pending_ = true;
}

int LcmDeviceTransport::PollSolverStatus(const StatusSink& sink) {
  if (!status_pending_) return 0;
  status_pending_ = false;
  try {
    sink(status_slot_.data(), static_cast<int>(status_size_));
  } catch (...) {
  }
  return 1;
}

bool LcmDeviceTransport::PublishDeviceState(const device_state_t& msg) {
  return messages::Publish(&lcm_, channels_.device_state, msg) == 0;
}

bool LcmDeviceTransport::PublishDeviceStatus(const device_status_t& msg) {
  return messages::Publish(&lcm_, channels_.device_status, msg) == 0;
}

int LcmDeviceTransport::PollForceModels(int wait_ms, const ForceModelSink& sink) {
  if (!lcm_.good()) return -1;
  sink_ = &sink;
  delivered_ = 0;
  int rc = status_pending_ ? 0 : lcm_.handleTimeout(wait_ms);
  // More may be queued: take them without waiting again (bounded, so a flood cannot
  // keep the caller from checking its stop flag). A status in the slot ends the round:
  // it is checked before another datagram can replace it, so forged statuses, however
  // many, cannot push a genuine one out unchecked.
  for (int i = 0; rc > 0 && !status_pending_ && i < kMaxPerPoll; ++i) rc = lcm_.handleTimeout(0);
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
