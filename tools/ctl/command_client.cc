#include "command_client.h"

#include <algorithm>

#include "auth/message_mac.h"
#include "messages/subscribe.h"
#include "messages/publish.h"
#include "messages/validate.h"
#include "realtime/clock.h"
#include "snapthread/command_t.hpp"

namespace snapthread::ctl {

namespace {

// Whether a received status or reply comes from the server: signed by its key (either
// slot, for a rotation's grace) and claiming the server's role.
template <class Msg>
bool FromServer(const lcm::ReceiveBuffer* rbuf, const std::string& channel, const Msg& decoded,
                const auth::KeySet& keys) {
  return decoded.sender_role == static_cast<int8_t>(auth::Role::kServer) &&
         auth::VerifySignature(rbuf->data, rbuf->data_size, channel, keys.server_public_key());
}

}  // namespace

CommandClient::CommandClient(lcm::LCM* lcm, const messages::Channels& channels,
                             const auth::KeySet& keys)
    : lcm_(lcm), channels_(channels), keys_(keys) {
  status_sub_ = messages::Subscribe<&CommandClient::OnStatus>(lcm_, channels_.solver_status, this);
  reply_sub_ = messages::Subscribe<&CommandClient::OnReply>(lcm_, channels_.command_reply, this);
}

CommandClient::~CommandClient() {
  if (status_sub_ != nullptr) lcm_->unsubscribe(status_sub_);
  if (reply_sub_ != nullptr) lcm_->unsubscribe(reply_sub_);
}

void CommandClient::OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  solver_status_t status;
  std::string why;
  if (!messages::DecodeAndValidate(rbuf, &status, &why) ||
      !FromServer(rbuf, channel, status, keys_) ||
      status_filter_.Admit(status.epoch, status.auth_seq) != auth::Reason::kAccepted) {
    ++refused_statuses_;
    return;
  }
  status_ = std::move(status);
  ++statuses_seen_;
}

void CommandClient::OnReply(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  command_reply_t reply;
  std::string why;
  if (!messages::DecodeAndValidate(rbuf, &reply, &why) ||
      !FromServer(rbuf, channel, reply, keys_) ||
      reply.epoch != status_filter_.epoch()) {
    ++refused_replies_;
    return;
  }
  // Another operator's command, or an earlier one of ours: not the answer awaited. Our
  // auth_seq is new, so a recorded reply cannot match it.
  if (awaited_auth_seq_ == 0 || reply.command_auth_seq != awaited_auth_seq_ ||
      reply.command != awaited_command_) {
    return;
  }
  reply_ = std::move(reply);
}

template <class Done>
bool CommandClient::HandleUntil(Clock::time_point deadline, Done done) {
  while (!done()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return done();
    const int wait_ms = static_cast<int>(std::min<int64_t>(left.count() + 1, 100));
    if (lcm_->handleTimeout(wait_ms) < 0) return false;
  }
  return true;
}

bool CommandClient::WaitForStatus(Clock::time_point deadline, solver_status_t* status) {
  const int64_t seen = statuses_seen_;
  if (!HandleUntil(deadline, [&] { return statuses_seen_ > seen; })) return false;
  *status = *status_;
  return true;
}

CommandOutcome CommandClient::Send(int8_t command, const std::string& argument,
                                   Clock::time_point deadline) {
  CommandOutcome out;
  if (!status_ && !HandleUntil(deadline, [&] { return status_.has_value(); })) {
    out.kind = CommandOutcome::Kind::kNoServer;
    return out;
  }
  command_t msg;
  msg.utime = realtime::RealtimeMicros();
  msg.command = command;
  msg.argument = argument;
  const int64_t seq = auth_seq_.Next();
  if (!auth::Sign(&msg, channels_.command, status_filter_.epoch(), seq, keys_.tagger()) ||
      messages::Publish(lcm_, channels_.command, msg) != 0) {
    out.kind = CommandOutcome::Kind::kNotSent;
    return out;
  }
  awaited_auth_seq_ = seq;
  awaited_command_ = command;
  reply_.reset();
  const bool answered = HandleUntil(deadline, [&] { return reply_.has_value(); });
  awaited_auth_seq_ = 0;
  if (!answered) {
    out.kind = CommandOutcome::Kind::kNoReply;
    return out;
  }
  out.kind = reply_->ok != 0 ? CommandOutcome::Kind::kApplied : CommandOutcome::Kind::kRefused;
  out.message = reply_->message;
  return out;
}

}  // namespace snapthread::ctl
