#include "client_pacer.h"

#include <algorithm>

namespace snapthread::web {

ClientPacer::ClientPacer(double max_rate_hz) {
  const auto interval = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / std::max(max_rate_hz, 1e-3)));
  slots_[Index(FeedKind::kShape)].min_interval = interval;
  slots_[Index(FeedKind::kForceModel)].min_interval = interval;
}

void ClientPacer::Offer(FeedKind kind, Text text) {
  Slot& slot = slots_[Index(kind)];
  if (slot.pending) dropped_[Index(kind)]++;
  slot.pending = std::move(text);
}

ClientPacer::Next ClientPacer::Take(Clock::time_point now) {
  // Low-rate kinds first (statuses, counters, replay position, pong: small, and a page's
  // panel should not wait behind shapes), then force, then shape.
  static constexpr FeedKind kOrder[] = {FeedKind::kPong,         FeedKind::kReplay,
                                        FeedKind::kSolverStatus, FeedKind::kDeviceStatus,
                                        FeedKind::kBridge,       FeedKind::kForceModel,
                                        FeedKind::kShape};
  Next next;
  for (const FeedKind kind : kOrder) {
    Slot& slot = slots_[Index(kind)];
    if (!slot.pending) continue;
    const bool paced = slot.min_interval > Clock::duration::zero();
    // A full window: the page's Ack() makes the session ask again.
    if (paced && in_flight_ >= kWindow) continue;
    const Clock::time_point allowed = slot.last_sent + slot.min_interval;
    if (now >= allowed || slot.last_sent == Clock::time_point{}) {
      next.text = std::move(slot.pending);
      slot.pending.reset();
      next.kind = kind;
      next.wait = false;
      slot.last_sent = now;
      sent_[Index(kind)]++;
      if (paced) in_flight_++;
      return next;
    }
    if (!next.wait || allowed < next.at) {
      next.wait = true;
      next.at = allowed;
    }
  }
  return next;
}

}  // namespace snapthread::web
