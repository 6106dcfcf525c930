#include "live_feed.h"

#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <type_traits>

#include "auth/freshness_filter.h"
#include "message_json.h"
#include "messages/channels.h"
#include "messages/lcm_url.h"
#include "messages/subscribe.h"
#include "messages/validate.h"
#include "observer_check.h"
#include "snapthread/device_status_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::web {
namespace {

// Authenticated devices tracked separately; more are refused. Only a device the server
// certified can add one (the certificate and the signature are checked before its name is
// used), so this bounds the server's mistakes, not a stranger's flood.
constexpr size_t kMaxDevices = 16;

std::string ToJson(const thread_shape_t& m) { return ShapeJson(m, DrawsSmooth(m.model)); }
std::string ToJson(const force_model_t& m) { return ForceModelJson(m); }
std::string ToJson(const solver_status_t& m) { return SolverStatusJson(m); }
std::string ToJson(const device_status_t& m) { return DeviceStatusJson(m); }

FeedKind KindOf(const thread_shape_t&) { return FeedKind::kShape; }
FeedKind KindOf(const force_model_t&) { return FeedKind::kForceModel; }
FeedKind KindOf(const solver_status_t&) { return FeedKind::kSolverStatus; }
FeedKind KindOf(const device_status_t&) { return FeedKind::kDeviceStatus; }

int64_t NowUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

LiveFeed::LiveFeed(const std::string& lcm_url, const std::string& session,
                   const auth::PublicKey& server_key, PublishFn publish)
    : lcm_(lcm_url), server_key_(server_key), publish_(std::move(publish)) {
  if (!lcm_.good()) {
    throw std::runtime_error("cannot open LCM at " + lcm_url + ". " + messages::LcmStartHint(lcm_url));
  }
  const messages::Channels channels(session);
  // Shapes come at ~60 Hz and force models at the update rate; LCM's default queue of 30
  // would drop bursts while this thread is off the CPU, so give them seconds of room.
  // (messages::Subscribe, not lcm_.subscribe: see messages/subscribe.h.)
  auto* shape =
      messages::Subscribe<&LiveFeed::OnMessage<thread_shape_t>>(lcm_, channels.shape, this);
  auto* model =
      messages::Subscribe<&LiveFeed::OnMessage<force_model_t>>(lcm_, channels.force_model, this);
  auto* solver = messages::Subscribe<&LiveFeed::OnMessage<solver_status_t>>(
      lcm_, channels.solver_status, this);
  auto* device = messages::Subscribe<&LiveFeed::OnMessage<device_status_t>>(
      lcm_, channels.device_status, this);
  // The device statuses of a genuine session come at ~1 Hz per device: room for a burst
  // of forged ones on the same channel (each refused in microseconds) before LCM, which
  // drops a full queue's newest, would drop a genuine one.
  if (shape) shape->setQueueCapacity(240);
  if (model) model->setQueueCapacity(4000);
  if (device) device->setQueueCapacity(240);
  subscriptions_ = {shape, model, solver, device};
}

LiveFeed::~LiveFeed() {
  Stop();
  for (auto* s : subscriptions_) {
    if (s != nullptr) lcm_.unsubscribe(s);
  }
}

void LiveFeed::Start() {
  if (running_.exchange(true)) return;
  thread_ = std::thread(&LiveFeed::Loop, this);
}

void LiveFeed::Stop() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
}

void LiveFeed::Loop() {
  while (running_) {
    if (lcm_.handleTimeout(kFlushMs) < 0) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const Clock::time_point now = Clock::now();
    PublishIfDue(&newest_shape_, now);
    PublishIfDue(&newest_model_, now);
  }
}

template <class Msg>
void LiveFeed::PublishIfDue(Newest<Msg>* newest, Clock::time_point now) {
  static const auto kInterval = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / kPublishHz));
  if (!newest->msg || now - newest->published < kInterval) return;
  newest->published = now;
  publish_(KindOf(*newest->msg), std::make_shared<const std::string>(ToJson(*newest->msg)));
  newest->msg.reset();
}

template <class Msg>
auth::FreshnessFilter* LiveFeed::FilterFor(const Msg& msg) {
  if constexpr (std::is_same_v<Msg, solver_status_t>) {
    return &status_filter_;
  } else {
    auth::FreshnessFilter* filter = nullptr;
    if constexpr (std::is_same_v<Msg, thread_shape_t>) filter = &shape_filter_;
    if constexpr (std::is_same_v<Msg, force_model_t>) filter = &model_filter_;
    if constexpr (std::is_same_v<Msg, device_status_t>) {
      auto it = device_filters_.find(msg.sender_name);
      if (it == device_filters_.end()) {
        if (device_filters_.size() >= kMaxDevices) return nullptr;
        it = device_filters_
                 .emplace(msg.sender_name, std::make_unique<auth::FreshnessFilter>(
                                               "DEVICE_STATUS " + msg.sender_name))
                 .first;
      }
      filter = it->second.get();
    }
    // Everything but the solver status is taken in the epoch that status taught us.
    if (filter->epoch() != status_filter_.epoch()) filter->SetEpoch(status_filter_.epoch());
    return filter;
  }
}

template <class Msg>
auth::FreshnessFilter* LiveFeed::BadMacCounter() {
  if constexpr (std::is_same_v<Msg, thread_shape_t>) return &shape_filter_;
  if constexpr (std::is_same_v<Msg, force_model_t>) return &model_filter_;
  if constexpr (std::is_same_v<Msg, solver_status_t>) return &status_filter_;
  if constexpr (std::is_same_v<Msg, device_status_t>) return &device_bad_mac_;
}

template <class Msg>
void LiveFeed::OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  // Force models between the server's display-rate ones carry no signature: they are for
  // the device, not for observers, and are skipped before any work.
  if (std::is_same_v<Msg, force_model_t> && viewer::SignaturesAbsent(rbuf->data, rbuf->data_size)) return;
  Msg msg;
  std::string why;
  if (!messages::DecodeAndValidate(rbuf, &msg, &why)) {
    malformed_++;
    return;
  }
  // The signature (and a device's certificate) before anything keyed by a field of the
  // message (a device name) is created. Its refusal is counted on the channel's counter.
  if (viewer::CheckObserved(rbuf->data, rbuf->data_size, channel, msg, server_key_) !=
      viewer::ObserverVerdict::kAccepted) {
    auth_rejected_++;
    auth::FreshnessFilter* counter = BadMacCounter<Msg>();
    counter->Reject(auth::Reason::kBadMac);
    LogRefusals(counter);
    return;
  }
  auth::FreshnessFilter* filter = FilterFor(msg);
  if (filter == nullptr) {  // a 17th certified device
    auth_rejected_++;
    return;
  }
  if (filter->Admit(msg.epoch, msg.auth_seq) != auth::Reason::kAccepted) {
    auth_rejected_++;
    LogRefusals(filter);
    return;
  }
  received_[Index(KindOf(msg))]++;
  if constexpr (std::is_same_v<Msg, thread_shape_t> || std::is_same_v<Msg, force_model_t>) {
    auto* newest = [this]() {
      if constexpr (std::is_same_v<Msg, thread_shape_t>) return &newest_shape_;
      else return &newest_model_;
    }();
    newest->msg = std::move(msg);
    PublishIfDue(newest, Clock::now());
  } else {
    publish_(KindOf(msg), std::make_shared<const std::string>(ToJson(msg)));
  }
}

void LiveFeed::LogRefusals(auth::FreshnessFilter* filter) {
  std::string line;
  if (filter->TakeLogLine(NowUs(), &line)) {
    std::fprintf(stderr, "snapthread-web: refused %s\n", line.c_str());
  }
}

FeedCounts LiveFeed::counts() const {
  FeedCounts c;
  for (int i = 0; i < 4; ++i) c.received[i] = received_[i].load();
  c.malformed = malformed_.load();
  c.auth_rejected = auth_rejected_.load();
  c.epoch = status_filter_.epoch();
  return c;
}

}  // namespace snapthread::web
