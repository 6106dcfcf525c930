// The viewer's LCM side: subscribes to <SESSION>_SHAPE and <SESSION>_SOLVER_STATUS, vets
// every message (bad ones are dropped and counted; handlers never throw) and keeps the latest
// of each for the render loop. LCM is handled on its own thread, so rendering never blocks
// on the network: liblcm's reader thread drains the socket into the subscription queue,
// the receiver's thread (Loop) vets each message into the latest-value slot, and the render
// loop copies the slot (Snapshot). The shape queue holds seconds of shapes, so a receiver
// thread the scheduler leaves off the CPU under load catches up instead of LCM dropping
// what arrives meanwhile; the renderer still only ever sees the latest shape.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "auth/freshness_filter.h"
#include "auth/key_id.h"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::viewer {

struct ForceSample {
  double time_s;   // receive time, seconds since the receiver started
  double force_n;  // |force_newtons|
};

// The server's shape sequence numbers (thread_shape_t::seq) against what arrived.
struct ShapeSequence {
  int64_t first = -1;    // first seq received (-1: none yet)
  int64_t highest = -1;  // highest seq received
  int64_t received = 0;  // valid shapes received
  // Published between first and highest but not received (lost or refused).
  int64_t Missed() const { return first < 0 ? 0 : highest - first + 1 - received; }
};

struct SessionSnapshot {
  bool has_shape = false;
  thread_shape_t shape;
  bool has_status = false;
  solver_status_t status;
  int64_t shapes_received = 0;   // valid shapes since start
  int64_t statuses_received = 0;
  int64_t bad_messages = 0;      // malformed messages dropped (both channels)
  int64_t auth_rejected = 0;     // refused by authentication (bad signature, role, epoch, sequence)
  double shape_rate_hz = 0.0;    // valid shapes over the last second
  std::vector<ForceSample> force_history;  // last kHistorySeconds
  double now_s = 0.0;            // seconds since the receiver started
};

class SessionReceiver {
 public:
  static constexpr double kHistorySeconds = 10.0;
  // Shapes LCM may queue for the receiver thread: 4 s at the server's 60 Hz.
  static constexpr int kShapeQueue = 240;

  // Subscribes on `lcm` (which must be good()). Call Start() to begin handling.
  // `session` must be a valid session name (messages::Channels throws otherwise).
  // With the server's public key (which must outlive the receiver) statuses are taken
  // only signed by the server (observer_check.h) with a fresh sequence (their epoch
  // adopted), and shapes only signed by the server, in that epoch and with a fresh
  // sequence (docs/security.md); nullptr checks nothing (tests).
  SessionReceiver(lcm::LCM* lcm, const std::string& session,
                  const auth::PublicKey* server_key = nullptr);
  ~SessionReceiver();
  SessionReceiver(const SessionReceiver&) = delete;
  SessionReceiver& operator=(const SessionReceiver&) = delete;

  void Start();
  void Stop();
  // Copies the current state; `with_history` false skips the force history copy.
  SessionSnapshot Snapshot(bool with_history = true) const;
  int64_t shapes_received() const { return shapes_received_.load(); }
  int64_t bad_messages() const { return bad_messages_.load(); }
  ShapeSequence shape_sequence() const;
  // The server epoch learned from an authenticated status (0: none yet).
  int64_t epoch() const { return status_filter_.epoch(); }
  int64_t auth_rejected() const {
    return static_cast<int64_t>(status_filter_.rejected() + shape_filter_.rejected());
  }
  std::string last_error() const;
  const std::string& shape_channel() const { return shape_channel_; }

 private:
  void OnShape(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void Loop();
  double NowS() const;
  // Authentication of one received message; false (counted, logged rate-limited) when
  // refused. LCM thread.
  template <class Msg>
  bool Authentic(const lcm::ReceiveBuffer* rbuf, const Msg& msg, const std::string& channel,
                 auth::FreshnessFilter* filter);

  lcm::LCM* lcm_;
  const auth::PublicKey* server_key_;
  auth::FreshnessFilter status_filter_{"SOLVER_STATUS", auth::FreshnessFilter::EpochPolicy::kAdopt};
  auth::FreshnessFilter shape_filter_{"SHAPE"};
  std::string shape_channel_;
  std::string status_channel_;
  std::vector<lcm::Subscription*> subscriptions_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<int64_t> shapes_received_{0};
  std::atomic<int64_t> bad_messages_{0};

  mutable std::mutex mutex_;  // guards everything below
  SessionSnapshot latest_;
  std::deque<double> shape_times_s_;
  std::deque<ForceSample> history_;
  ShapeSequence sequence_;
  std::string last_error_;
};

}  // namespace snapthread::viewer
