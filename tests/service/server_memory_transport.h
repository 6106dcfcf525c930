// An in-memory ServerTransport (server/server_transport.h), so a whole Server runs in one
// process without LCM: the test delivers datagrams as a device or an operator would send
// them (test_support::Encode, sample_messages.h), and listens to what the server
// publishes, encoded as it would go on the wire.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/role.h"
#include "sample_messages.h"
#include "server_transport.h"

namespace snapthread::server::testing {

// What the server publishes on.
enum class Outbound { kForceModel, kShape, kSolverStatus, kCommandReply };

class MemoryServerTransport final : public ServerTransport {
 public:
  // Called on the publishing thread (the server's solve thread) with each message.
  using Listener = std::function<void(Outbound channel, const std::vector<uint8_t>& bytes)>;

  // Before the server starts.
  void AddListener(Listener listener) { listeners_.push_back(std::move(listener)); }
  // Every publish refused from now on (the server counts publish failures).
  void RefusePublishing(bool refuse) { refuse_ = refuse; }

  // The senders' side: bytes the receive thread hands to the server's gate, in order.
  void DeliverDeviceState(std::vector<uint8_t> bytes) { Deliver(false, std::move(bytes)); }
  void DeliverCommand(std::vector<uint8_t> bytes) { Deliver(true, std::move(bytes)); }

  bool PublishForceModel(const force_model_t& msg) override {
    return Send(Outbound::kForceModel, msg);
  }
  bool PublishShape(const thread_shape_t& msg) override { return Send(Outbound::kShape, msg); }
  bool PublishSolverStatus(const solver_status_t& msg) override {
    return Send(Outbound::kSolverStatus, msg);
  }
  bool PublishCommandReply(const command_reply_t& msg) override {
    return Send(Outbound::kCommandReply, msg);
  }

  int Receive(int wait_ms, InboundSink* sink) override {
    std::deque<Datagram> taken;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait_for(lock, std::chrono::milliseconds(wait_ms), [&] { return !inbox_.empty(); });
      taken.swap(inbox_);
    }
    for (const Datagram& d : taken) {
      if (d.command) {
        sink->OnCommand(d.bytes.data(), d.bytes.size());
      } else {
        sink->OnDeviceState(d.bytes.data(), d.bytes.size());
      }
    }
    return static_cast<int>(taken.size());
  }

  std::string Describe() const override { return "memory"; }

 private:
  struct Datagram {
    bool command = false;
    std::vector<uint8_t> bytes;
  };

  void Deliver(bool command, std::vector<uint8_t> bytes) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      inbox_.push_back(Datagram{command, std::move(bytes)});
    }
    cv_.notify_one();
  }

  template <class Msg>
  bool Send(Outbound channel, const Msg& msg) {
    if (refuse_) return false;
    const std::vector<uint8_t> bytes = test_support::Encode(msg);  // as on the wire
    for (const Listener& listener : listeners_) listener(channel, bytes);
    return true;
  }

  std::vector<Listener> listeners_;
  std::atomic<bool> refuse_{false};
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Datagram> inbox_;
};

// Credentials issued from the session's root, as snapthread-keygen issues them: a device
// (named as the grasp it drives; "hand" for a scene's single unnamed grasp) and an operator.
inline auth::KeySet DeviceKeys(const auth::SessionKey& root, const std::string& name = "hand",
                               int64_t expires_unix_s = auth::kNeverExpires) {
  return auth::KeySet::ForRole(root, auth::Role::kDevice, name, expires_unix_s);
}
inline auth::KeySet OperatorKeys(const auth::SessionKey& root, const std::string& name = "ops") {
  return auth::KeySet::ForRole(root, auth::Role::kOperator, name);
}

// `msg` tagged by `sender` for `channel` and encoded as it goes on the wire.
template <class Msg>
std::vector<uint8_t> Tagged(Msg msg, const std::string& channel, int64_t epoch, int64_t auth_seq,
                            const auth::Tagger& sender) {
  if (!auth::Sign(&msg, channel, epoch, auth_seq, sender)) return {};
  return test_support::Encode(msg);
}

}  // namespace snapthread::server::testing
