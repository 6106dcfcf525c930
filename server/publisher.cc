#include "publisher.h"

#include <spdlog/spdlog.h>

namespace snapthread::server {

Publisher::Publisher(ServerTransport* transport, const messages::Channels& channels,
                     const auth::SessionKey& key, int64_t epoch, ServerCounters* counters)
    : transport_(transport), channels_(channels), key_(key), epoch_(epoch), counters_(counters) {}

template <class Msg>
bool Publisher::Sign(Msg* msg, const std::string& channel) {
  if (auth::Sign(msg, channel, epoch_, auth_seq_.Next(), key_)) return true;
  counters_->publish_failures.fetch_add(1);
  if (ShouldLog(&counters_->last_solve_error_log_us)) {
    spdlog::error("server: could not sign a message for {}; not sent", channel);
  }
  return false;
}

bool Publisher::ForceModel(force_model_t* msg) {
  if (!Sign(msg, channels_.force_model)) return false;
  if (!transport_->PublishForceModel(*msg)) {
    counters_->publish_failures.fetch_add(1);
    return false;
  }
  return true;
}

bool Publisher::Shape(thread_shape_t* msg) {
  if (!Sign(msg, channels_.shape)) return false;
  if (!transport_->PublishShape(*msg)) {
    counters_->publish_failures.fetch_add(1);
    return false;
  }
  counters_->shapes_published.fetch_add(1);
  return true;
}

bool Publisher::SolverStatus(solver_status_t* msg) {
  if (!Sign(msg, channels_.solver_status)) return false;
  if (!transport_->PublishSolverStatus(*msg)) {
    counters_->publish_failures.fetch_add(1);
    return false;
  }
  counters_->statuses_published.fetch_add(1);
  return true;
}

}  // namespace snapthread::server
