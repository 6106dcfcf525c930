#include "session_receiver.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "observer_check.h"
#include "shape_check.h"
#include "messages/channels.h"
#include "messages/subscribe.h"

namespace snapthread::viewer {

SessionReceiver::SessionReceiver(lcm::LCM* lcm, const std::string& session,
                                 const auth::PublicKey* server_key)
    : lcm_(lcm),
      server_key_(server_key),
      shape_channel_(messages::Channels(session).shape),
      status_channel_(messages::Channels(session).solver_status) {
  lcm::Subscription* shapes =
      messages::Subscribe<&SessionReceiver::OnShape>(lcm_, shape_channel_, this);
  lcm::Subscription* statuses =
      messages::Subscribe<&SessionReceiver::OnStatus>(lcm_, status_channel_, this);
  // LCM's reader thread drops what arrives while a subscription's queue is full (its
  // default is 30 messages). Statuses (10 Hz) only update the overlay; every shape counts.
  if (shapes != nullptr) shapes->setQueueCapacity(kShapeQueue);
  if (statuses != nullptr) statuses->setQueueCapacity(4);
  subscriptions_ = {shapes, statuses};
}

SessionReceiver::~SessionReceiver() {
  Stop();
  for (auto* s : subscriptions_) {
    if (s != nullptr) lcm_->unsubscribe(s);
  }
}

void SessionReceiver::Start() {
  if (running_.exchange(true)) return;
  thread_ = std::thread(&SessionReceiver::Loop, this);
}

void SessionReceiver::Stop() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
}

void SessionReceiver::Loop() {
  while (running_) {
    // Bounded wait so Stop() is honoured within 50 ms.
    if (lcm_->handleTimeout(50) < 0) {
      std::lock_guard<std::mutex> lock(mutex_);
      last_error_ = "lcm handle failed";
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
}

double SessionReceiver::NowS() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

template <class Msg>
bool SessionReceiver::Authentic(const lcm::ReceiveBuffer* rbuf, const Msg& msg,
                                const std::string& channel, auth::FreshnessFilter* filter) {
  if (server_key_ == nullptr) return true;
  if (filter == &shape_filter_ && shape_filter_.epoch() != status_filter_.epoch()) {
    shape_filter_.SetEpoch(status_filter_.epoch());
  }
  if (CheckObserved(rbuf->data, rbuf->data_size, channel, msg, *server_key_) != ObserverVerdict::kAccepted) {
    filter->Reject(auth::Reason::kBadMac);  // a bad signature: counted with the bad MACs
  } else if (filter->Admit(msg.epoch, msg.auth_seq) == auth::Reason::kAccepted) {
    return true;
  }
  std::string line;
  const int64_t now_us = static_cast<int64_t>(1e6 * NowS());
  if (filter->TakeLogLine(now_us, &line)) {
    std::fprintf(stderr, "snapthread-viewer: refused %s\n", line.c_str());
    std::lock_guard<std::mutex> lock(mutex_);
    last_error_ = line;
  }
  return false;
}

void SessionReceiver::OnShape(const lcm::ReceiveBuffer* rbuf, const std::string&) {
  thread_shape_t shape;
  std::string why;
  if (!DecodeShape(rbuf->data, static_cast<int>(rbuf->data_size), &shape, &why)) {
    bad_messages_++;
    std::lock_guard<std::mutex> lock(mutex_);
    latest_.bad_messages = bad_messages_.load();
    last_error_ = shape_channel_ + ": " + why;
    return;
  }
  if (!Authentic(rbuf, shape, shape_channel_, &shape_filter_)) return;
  const double now = NowS();
  const double f = std::sqrt(shape.force_newtons[0] * shape.force_newtons[0] +
                             shape.force_newtons[1] * shape.force_newtons[1] +
                             shape.force_newtons[2] * shape.force_newtons[2]);
  std::lock_guard<std::mutex> lock(mutex_);
  latest_.shape = std::move(shape);
  latest_.has_shape = true;
  latest_.shapes_received = ++shapes_received_;
  if (sequence_.first < 0) sequence_.first = latest_.shape.seq;
  sequence_.highest = std::max(sequence_.highest, latest_.shape.seq);
  sequence_.received++;
  shape_times_s_.push_back(now);
  while (!shape_times_s_.empty() && shape_times_s_.front() < now - 1.0) shape_times_s_.pop_front();
  history_.push_back({now, f});
  while (!history_.empty() && history_.front().time_s < now - kHistorySeconds) {
    history_.pop_front();
  }
}

void SessionReceiver::OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string&) {
  solver_status_t status;
  std::string why;
  if (!DecodeSolverStatus(rbuf->data, static_cast<int>(rbuf->data_size), &status, &why)) {
    bad_messages_++;
    std::lock_guard<std::mutex> lock(mutex_);
    latest_.bad_messages = bad_messages_.load();
    last_error_ = status_channel_ + ": " + why;
    return;
  }
  if (!Authentic(rbuf, status, status_channel_, &status_filter_)) return;
  std::lock_guard<std::mutex> lock(mutex_);
  latest_.status = std::move(status);
  latest_.has_status = true;
  latest_.statuses_received++;
}

SessionSnapshot SessionReceiver::Snapshot(bool with_history) const {
  const double now = NowS();
  std::lock_guard<std::mutex> lock(mutex_);
  SessionSnapshot s = latest_;
  s.bad_messages = bad_messages_.load();
  s.auth_rejected = auth_rejected();
  s.now_s = now;
  int recent = 0;
  for (double t : shape_times_s_) recent += (t >= now - 1.0);
  s.shape_rate_hz = recent;
  if (with_history) s.force_history.assign(history_.begin(), history_.end());
  return s;
}

ShapeSequence SessionReceiver::shape_sequence() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return sequence_;
}

std::string SessionReceiver::last_error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_error_;
}

}  // namespace snapthread::viewer
