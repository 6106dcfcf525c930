// The production DeviceTransport: LCM on the session's channels (messages/channels.h).
#pragma once

#include <memory>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "messages/channels.h"
#include "transport.h"

namespace snapthread::device {

class LcmDeviceTransport final : public DeviceTransport {
 public:
  // Opens LCM on url (already resolved: messages/lcm_url.h) and subscribes to the
  // session's FORCE_MODEL channel. Check good() before use.
  LcmDeviceTransport(const std::string& url, const std::string& session);
  ~LcmDeviceTransport() override;
  LcmDeviceTransport(const LcmDeviceTransport&) = delete;
  LcmDeviceTransport& operator=(const LcmDeviceTransport&) = delete;

  bool good() const { return lcm_.good(); }

  bool PublishDeviceState(const device_state_t& msg) override;
  bool PublishDeviceStatus(const device_status_t& msg) override;
  // handleTimeout(wait_ms) until nothing more is waiting. One thread only.
  int PollForceModels(int wait_ms, const ForceModelSink& sink) override;

 private:
  static constexpr int kMaxPerPoll = 1000;

  void Handle(const lcm::ReceiveBuffer* rbuf, const std::string& channel);

  lcm::LCM lcm_;
  transport::Channels channels_;
  lcm::Subscription* subscription_ = nullptr;
  const ForceModelSink* sink_ = nullptr;  // set during PollForceModels only
  int delivered_ = 0;
};

}  // namespace snapthread::device
