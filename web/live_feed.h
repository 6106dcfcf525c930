// The bridge's LCM side in live mode: subscribes to <SESSION>_SHAPE, _FORCE_MODEL,
// _SOLVER_STATUS and _DEVICE_STATUS, vets every message as the viewer does (the exact
// decode, messages::DecodeAndValidate; then what an observer checks, viewer/observer_check.h:
// the server's signature for what the server publishes, the server's certificate and the
// device's signature for a device status; then the server epoch learned from an
// authenticated solver status and a strictly increasing auth_seq per sender) and hands
// each accepted one, as JSON, to `publish`. Per-sender state (a device's sequence floor)
// is made only for a message whose signature passed, and the slots below hold only
// accepted messages, so a sender without the server's signature (or its certificate) can
// neither fill the device table nor replace what the pages are shown. Force models the
// server did not sign (it signs them at display rate only) are skipped uncounted. Bad and
// refused messages are dropped and counted; handlers never throw. LCM is handled on the
// feed's own thread.
// Shapes and force models come faster than any page is sent them (signed force models at
// up to 60/s; a page gets at most 60/s of each): every one is
// vetted and counted, but only the newest is turned into JSON, at most kPublishHz times a
// second per kind, and the newest of a burst once it ends (the loop publishes it at most
// 1/kPublishHz + kFlushMs after the one before), so the bridge does not spend its CPU on
// JSON no page gets.
#pragma once

#include <array>
#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "auth/freshness_filter.h"
#include "auth/key_id.h"
#include "feed_kind.h"
#include "client_pacer.h"
#include "snapthread/force_model_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::web {

// Called on the feed's thread with each accepted message.
using PublishFn = std::function<void(FeedKind, Text)>;

struct FeedCounts {
  std::array<int64_t, 4> received{};  // accepted, per session kind (FeedKind 0..3)
  int64_t malformed = 0;              // failed DecodeAndValidate
  int64_t auth_rejected = 0;          // bad signature or certificate, foreign epoch, stale sequence
  int64_t epoch = 0;                  // the server epoch learned (0: none yet)
};

class LiveFeed {
 public:
  // Twice the pages' 60 Hz bound, so what the pacer picks is at most ~8 ms older.
  static constexpr double kPublishHz = 120.0;
  static constexpr int kFlushMs = 5;

  // Opens LCM at `lcm_url` and subscribes; throws std::runtime_error when LCM cannot start
  // or `session` is not a valid session name. `server_key` (the server's public key, from
  // the observer credential) must outlive the feed.
  LiveFeed(const std::string& lcm_url, const std::string& session, const auth::PublicKey& server_key,
           PublishFn publish);
  ~LiveFeed();
  LiveFeed(const LiveFeed&) = delete;
  LiveFeed& operator=(const LiveFeed&) = delete;

  void Start();
  void Stop();
  FeedCounts counts() const;

 private:
  template <class Msg>
  void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  template <class Msg>
  auth::FreshnessFilter* FilterFor(const Msg& msg);
  // Where a bad signature on Msg's channel is counted (and logged from).
  template <class Msg>
  auth::FreshnessFilter* BadMacCounter();
  static void LogRefusals(auth::FreshnessFilter* filter);
  void Loop();
  // The newest accepted shape or force model not yet published, and when its kind last was.
  template <class Msg>
  struct Newest {
    std::optional<Msg> msg;
    Clock::time_point published{};
  };
  template <class Msg>
  void PublishIfDue(Newest<Msg>* newest, Clock::time_point now);

  lcm::LCM lcm_;
  const auth::PublicKey& server_key_;
  PublishFn publish_;
  std::vector<lcm::Subscription*> subscriptions_;
  auth::FreshnessFilter status_filter_{"SOLVER_STATUS", auth::FreshnessFilter::EpochPolicy::kAdopt};
  auth::FreshnessFilter shape_filter_{"SHAPE"};
  auth::FreshnessFilter model_filter_{"FORCE_MODEL"};
  // One sequence per certified device name (each signs its statuses with its own auth_seq).
  std::map<std::string, std::unique_ptr<auth::FreshnessFilter>> device_filters_;
  auth::FreshnessFilter device_bad_mac_{"DEVICE_STATUS"};  // counts bad signatures only
  Newest<thread_shape_t> newest_shape_;
  Newest<force_model_t> newest_model_;
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::array<std::atomic<int64_t>, 4> received_{};
  std::atomic<int64_t> malformed_{0};
  std::atomic<int64_t> auth_rejected_{0};  // bad signature, refused by a filter, or a 17th device
};

}  // namespace snapthread::web
