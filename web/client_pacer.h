// What one page is sent next: a latest-value slot per feed kind, so a client that reads
// slowly has older values overwritten (latest wins) and never an unbounded queue, and a
// minimum interval per kind, so shapes and force models reach a page at most
// max_rate_hz (60) however fast the session publishes them. A browser takes whatever TCP
// brings into its own queue, so a page whose script falls behind would still get every
// paced message, late: the page acknowledges each shape and force model ("ack"), and at
// most kWindow of them are unacknowledged at a time; meanwhile the slots keep only the
// latest. Pure logic on the io thread: the WebSocket session asks Take() whenever it may
// write.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "feed_kind.h"

namespace snapthread::web {

using Clock = std::chrono::steady_clock;
using Text = std::shared_ptr<const std::string>;

class ClientPacer {
 public:
  // Shapes and force models at most `max_rate_hz`; the other kinds as they come.
  // Paced messages (shapes and force models) sent and not yet acknowledged, at most.
  static constexpr int kWindow = 32;  // ~270 ms of 120 messages/s

  explicit ClientPacer(double max_rate_hz = 60.0);

  // The page has handled one paced message.
  void Ack() {
    if (in_flight_ > 0) in_flight_--;
  }
  int in_flight() const { return in_flight_; }

  // Stores `text` as the latest of its kind (replacing one not yet sent: counted as
  // dropped).
  void Offer(FeedKind kind, Text text);

  struct Next {
    Text text;                    // null: nothing may be sent now
    FeedKind kind = FeedKind::kShape;
    bool wait = false;            // with null text: something is paced until `at` (an
                                  // acknowledgement may be what it waits for as well)
    Clock::time_point at{};
  };
  // The next message to send at `now` (the status kinds first, then the force model, then
  // the shape), marking it sent; or, when the pending ones are all paced, when to ask again.
  Next Take(Clock::time_point now);

  int64_t sent(FeedKind kind) const { return sent_[Index(kind)]; }
  int64_t dropped(FeedKind kind) const { return dropped_[Index(kind)]; }

 private:
  struct Slot {
    Text pending;
    Clock::time_point last_sent{};
    Clock::duration min_interval{};
  };
  std::array<Slot, kFeedKinds> slots_{};
  std::array<int64_t, kFeedKinds> sent_{};
  std::array<int64_t, kFeedKinds> dropped_{};
  int in_flight_ = 0;
};

}  // namespace snapthread::web
