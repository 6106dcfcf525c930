#include "publisher.h"

#include <spdlog/spdlog.h>

namespace snapthread::server {

Publisher::Publisher(ServerTransport* transport, const messages::Channels& channels,
                     const auth::SessionKey& key, int64_t epoch, ServerCounters* counters)
    : transport_(transport), channels_(channels), key_(key), epoch_(epoch), counters_(counters) {}

template <class Msg, class PublishFn>
bool Publisher::Send(Msg* msg, const std::string& channel, PublishFn publish,
                     std::atomic<int64_t>* published) {
  if (!auth::Sign(msg, channel, epoch_, auth_seq_.Next(), key_)) {
    counters_->publish_failures.fetch_add(1);
    if (ShouldLog(&counters_->last_solve_error_log_us)) {
      spdlog::error("server: could not sign a message for {}; not sent", channel);
    }
    return false;
  }
  if (!publish(*msg)) {
    counters_->publish_failures.fetch_add(1);
    return false;
  }
  if (published != nullptr) published->fetch_add(1);
  return true;
}

bool Publisher::ForceModel(force_model_t* msg) {
  return Send(msg, channels_.force_model,
              [this](const force_model_t& m) { return transport_->PublishForceModel(m); }, nullptr);
}

bool Publisher::Shape(thread_shape_t* msg) {
  return Send(msg, channels_.shape,
              [this](const thread_shape_t& m) { return transport_->PublishShape(m); },
              &counters_->shapes_published);
}

bool Publisher::SolverStatus(solver_status_t* msg) {
  return Send(msg, channels_.solver_status,
              [this](const solver_status_t& m) { return transport_->PublishSolverStatus(m); },
              &counters_->statuses_published);
}

bool Publisher::CommandReply(command_reply_t* msg) {
  return Send(msg, channels_.command_reply,
              [this](const command_reply_t& m) { return transport_->PublishCommandReply(m); },
              nullptr);
}

}  // namespace snapthread::server
