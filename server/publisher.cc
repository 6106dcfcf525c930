#include "publisher.h"

#include <spdlog/spdlog.h>

namespace snapthread::server {

Publisher::Publisher(ServerTransport* transport, const messages::Channels& channels, const ServerKeys* keys,
                     int64_t epoch, ServerCounters* counters)
    : transport_(transport), channels_(channels), keys_(keys), epoch_(epoch), counters_(counters) {
  server_tagger_.role = auth::Role::kServer;
  model_tagger_.role = auth::Role::kServer;
}

void Publisher::SetSigners(auth::Tagger* tagger) const {
  const ServerSigners& signers = keys_->signers();
  tagger->signer = &signers.current;
  tagger->previous_signer = signers.PreviousAt(UnixSeconds());
}

template <class Msg, class PublishFn>
bool Publisher::Send(Msg* msg, const std::string& channel, const auth::Tagger& tagger, PublishFn publish,
                     std::atomic<int64_t>* published) {
  if (!auth::Sign(msg, channel, epoch_, auth_seq_.Next(), tagger)) {
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

bool Publisher::ForceModel(force_model_t* msg, int grasp, const DeviceKey* device) {
  if (device == nullptr || grasp < 0) {
    counters_->publish_failures.fetch_add(1);
    return false;
  }
  model_tagger_.name.assign(device->name);  // reuses the capacity
  model_tagger_.expires_unix_s = device->expires_unix_s;
  model_tagger_.key_id = device->key_id;
  model_tagger_.mac_key = &device->key;
  const size_t slot = static_cast<size_t>(grasp);
  if (slot >= last_signed_model_us_.size()) last_signed_model_us_.resize(slot + 1, 0);
  const int64_t now_us = SteadyMicros();
  const bool sign = last_signed_model_us_[slot] == 0 || now_us - last_signed_model_us_[slot] >= kModelSignPeriodUs;
  if (sign) {
    SetSigners(&model_tagger_);
    last_signed_model_us_[slot] = now_us;
  } else {
    model_tagger_.signer = nullptr;
    model_tagger_.previous_signer = nullptr;
  }
  const bool sent = Send(msg, channels_.force_model, model_tagger_,
                         [this](const force_model_t& m) { return transport_->PublishForceModel(m); }, nullptr);
  model_tagger_.mac_key = nullptr;
  return sent;
}

bool Publisher::Shape(thread_shape_t* msg) {
  SetSigners(&server_tagger_);
  return Send(msg, channels_.shape, server_tagger_,
              [this](const thread_shape_t& m) { return transport_->PublishShape(m); },
              &counters_->shapes_published);
}

bool Publisher::SolverStatus(solver_status_t* msg) {
  SetSigners(&server_tagger_);
  return Send(msg, channels_.solver_status, server_tagger_,
              [this](const solver_status_t& m) { return transport_->PublishSolverStatus(m); },
              &counters_->statuses_published);
}

bool Publisher::CommandReply(command_reply_t* msg) {
  SetSigners(&server_tagger_);
  return Send(msg, channels_.command_reply, server_tagger_,
              [this](const command_reply_t& m) { return transport_->PublishCommandReply(m); }, nullptr);
}

}  // namespace snapthread::server
