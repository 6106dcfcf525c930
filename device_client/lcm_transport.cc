#include "lcm_transport.h"

namespace snapthread::device {

LcmDeviceTransport::LcmDeviceTransport(const std::string& url, const std::string& session)
    : lcm_(url), channels_(session) {
  if (lcm_.good()) {
    subscription_ = lcm_.subscribe(channels_.force_model, &LcmDeviceTransport::Handle, this);
  }
}

LcmDeviceTransport::~LcmDeviceTransport() {
  if (subscription_ != nullptr) lcm_.unsubscribe(subscription_);
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
