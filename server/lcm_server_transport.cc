#include "lcm_server_transport.h"

#include "messages/lcm_url.h"
#include "messages/subscribe.h"
#include "messages/publish.h"

namespace snapthread::server {

LcmServerTransport::LcmServerTransport(const std::string& url, const std::string& session)
    : owned_(std::make_unique<lcm::LCM>(url)), lcm_(owned_.get()), url_(url), channels_(session) {
  if (!lcm_->good()) {
    throw LcmInitError("LCM failed to start on " + url_ + ": " + messages::LcmStartHint(url_));
  }
  Subscribe();
}

LcmServerTransport::LcmServerTransport(lcm::LCM* lcm, const std::string& session)
    : lcm_(lcm), url_("(provided)"), channels_(session) {
  Subscribe();
}

LcmServerTransport::~LcmServerTransport() {
  if (state_sub_ != nullptr) lcm_->unsubscribe(state_sub_);
  if (command_sub_ != nullptr) lcm_->unsubscribe(command_sub_);
}

void LcmServerTransport::Subscribe() {
  state_sub_ = messages::Subscribe<&LcmServerTransport::HandleDeviceState>(
      lcm_, channels_.device_state, this);
  command_sub_ =
      messages::Subscribe<&LcmServerTransport::HandleCommand>(lcm_, channels_.command, this);
}

bool LcmServerTransport::PublishForceModel(const force_model_t& msg) {
  return messages::Publish(lcm_, channels_.force_model, msg) == 0;
}

bool LcmServerTransport::PublishShape(const thread_shape_t& msg) {
  return messages::Publish(lcm_, channels_.shape, msg) == 0;
}

bool LcmServerTransport::PublishSolverStatus(const solver_status_t& msg) {
  return messages::Publish(lcm_, channels_.solver_status, msg) == 0;
}

bool LcmServerTransport::PublishCommandReply(const command_reply_t& msg) {
  return messages::Publish(lcm_, channels_.command_reply, msg) == 0;
}

int LcmServerTransport::Receive(int wait_ms, InboundSink* sink) {
  sink_ = sink;
  const int rc = lcm_->handleTimeout(wait_ms);
  sink_ = nullptr;
  return rc < 0 ? -1 : rc;
}

// LCM handlers must never throw; the sink does not.
void LcmServerTransport::HandleDeviceState(const lcm::ReceiveBuffer* rbuf,
                                           const std::string& /*channel*/) {
  Hand(rbuf, false);
}

void LcmServerTransport::HandleCommand(const lcm::ReceiveBuffer* rbuf,
                                       const std::string& /*channel*/) {
  Hand(rbuf, true);
}

void LcmServerTransport::Hand(const lcm::ReceiveBuffer* rbuf, bool command) {
  if (sink_ == nullptr) return;
  const void* data = rbuf != nullptr ? rbuf->data : nullptr;
  const size_t size = rbuf != nullptr ? rbuf->data_size : 0;
  if (command) {
    sink_->OnCommand(data, size);
  } else {
    sink_->OnDeviceState(data, size);
  }
}

}  // namespace snapthread::server
