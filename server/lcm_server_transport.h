// The production ServerTransport: LCM on the session's channels (messages/channels.h).
// It either opens its own LCM on a URL (snapthread-server) or borrows the caller's
// instance (tests of the LCM path itself over memq://; that instance's other
// subscriptions are then dispatched on the server's receive thread as well).
#pragma once

#include <memory>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "messages/channels.h"
#include "server_transport.h"

namespace snapthread::server {

class LcmServerTransport final : public ServerTransport {
 public:
  // Opens LCM on url (already resolved: messages/lcm_url.h); LcmInitError naming the URL
  // and the usual fix when it does not start.
  LcmServerTransport(const std::string& url, const std::string& session);
  // Uses *lcm, which must outlive the transport.
  LcmServerTransport(lcm::LCM* lcm, const std::string& session);
  ~LcmServerTransport() override;
  LcmServerTransport(const LcmServerTransport&) = delete;
  LcmServerTransport& operator=(const LcmServerTransport&) = delete;

  bool PublishForceModel(const force_model_t& msg) override;
  bool PublishShape(const thread_shape_t& msg) override;
  bool PublishSolverStatus(const solver_status_t& msg) override;
  bool PublishCommandReply(const command_reply_t& msg) override;
  // One handleTimeout(wait_ms): at most one datagram per call.
  int Receive(int wait_ms, InboundSink* sink) override;
  std::string Describe() const override { return url_; }

 private:
  void Subscribe();
  void HandleDeviceState(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void HandleCommand(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  // The received bytes to the sink's OnCommand or OnDeviceState (during Receive only).
  void Hand(const lcm::ReceiveBuffer* rbuf, bool command);

  std::unique_ptr<lcm::LCM> owned_;
  lcm::LCM* lcm_ = nullptr;
  std::string url_;
  messages::Channels channels_;
  lcm::Subscription* state_sub_ = nullptr;
  lcm::Subscription* command_sub_ = nullptr;
  InboundSink* sink_ = nullptr;  // set during Receive only
};

}  // namespace snapthread::server
