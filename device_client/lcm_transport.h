// The production DeviceTransport: LCM on the session's channels (messages/channels.h).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

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
  // A solver status is larger than this only when it cannot be valid (three strings of
  // at most 4096 bytes and ~250 bytes of numbers): it is dropped unread and counted.
  static constexpr size_t kMaxStatusBytes = 16 * 1024;

  // handleTimeout(wait_ms), then handleTimeout(0) until nothing more is waiting, or until
  // a solver status is waiting in the slot: then it returns at once, so the caller checks
  // that status (PollSolverStatus) before the next datagram is read. One thread only.
  int PollForceModels(int wait_ms, const ForceModelSink& sink) override;
  // The status in the slot, if any (0 or 1).
  int PollSolverStatus(const StatusSink& sink) override;

  // Unchecked statuses replaced by a newer one before they were polled (latest wins; 0
  // when the caller polls after every PollForceModels, as DeviceClient does), and those
  // dropped for their size.
  uint64_t statuses_superseded() const { return statuses_superseded_.load(); }
  uint64_t statuses_oversized() const { return statuses_oversized_.load(); }

 private:
  static constexpr int kMaxPerPoll = 1000;

  void Handle(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void HandleStatus(const lcm::ReceiveBuffer* rbuf, const std::string& channel);

  lcm::LCM lcm_;
  messages::Channels channels_;
  lcm::Subscription* subscription_ = nullptr;
  lcm::Subscription* status_subscription_ = nullptr;
  // The latest unchecked solver status: one slot of kMaxStatusBytes, allocated once, so
  // neither a flood nor a huge datagram allocates or queues anything. Receive thread only.
  std::vector<uint8_t> status_slot_;
  size_t status_size_ = 0;
  bool status_pending_ = false;
  std::atomic<uint64_t> statuses_superseded_{0};
  std::atomic<uint64_t> statuses_oversized_{0};
  const ForceModelSink* sink_ = nullptr;  // set during PollForceModels only
  int delivered_ = 0;
};

}  // namespace snapthread::device
