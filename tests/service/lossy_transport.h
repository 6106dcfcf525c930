// An in-process lossy, reordering network for a DeviceClient (issue 12 item 4): a
// DeviceTransport that wraps another one (the InMemoryTransport a server fake reads and
// writes, device_fakes.h) and puts a seeded delay line in each direction. Each message is
// lost with probability `loss`, otherwise it arrives delay_us ± jitter_us later (uniform),
// so two messages sent 1 ms apart swap places whenever their delays differ by more than
// that: at 5 ± 2 ms, about a third of neighbouring pairs.
//
// Time is the test's fake clock; messages move only when the client publishes or polls
// (the test drives both every tick), so a run is exactly repeatable for a seed.
#pragma once

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "sim_clock.h"
#include "transport.h"

namespace snapthread::device::testing {

struct LinkOptions {
  double loss = 0.2;          // probability that a message is lost
  int64_t delay_us = 5000;    // mean one-way delay
  int64_t jitter_us = 2000;   // delay spread: uniform in [delay - jitter, delay + jitter]
  uint32_t seed = 1;
};

// One direction of the link: messages in, the ones due out in order of arrival.
template <class T>
class DelayLine {
 public:
  DelayLine(const LinkOptions& options, uint32_t seed)
      : options_(options), rng_(seed), delay_us_(options.delay_us - options.jitter_us,
                                                options.delay_us + options.jitter_us) {}

  void Send(T item, int64_t now_us) {
    if (lose_(rng_) < options_.loss) {
      ++lost_;
      return;
    }
    in_flight_.push_back({now_us + delay_us_(rng_), sent_++, std::move(item)});
  }

  // Hands every message due at now_us to f, earliest arrival first; returns how many.
  template <class F>
  int DeliverDue(int64_t now_us, F&& f) {
    std::stable_sort(in_flight_.begin(), in_flight_.end(),
                     [](const Flight& a, const Flight& b) { return a.due_us < b.due_us; });
    int n = 0;
    while (n < static_cast<int>(in_flight_.size()) && in_flight_[n].due_us <= now_us) {
      const Flight& m = in_flight_[n];
      if (m.order < last_order_) ++reordered_;  // overtaken by a later message
      last_order_ = std::max(last_order_, m.order);
      f(m.item);
      ++n;
    }
    in_flight_.erase(in_flight_.begin(), in_flight_.begin() + n);
    return n;
  }

  uint64_t lost() const { return lost_; }
  uint64_t reordered() const { return reordered_; }

 private:
  struct Flight {
    int64_t due_us;
    uint64_t order;  // sending order
    T item;
  };
  LinkOptions options_;
  std::mt19937 rng_;
  std::uniform_real_distribution<double> lose_{0.0, 1.0};
  std::uniform_int_distribution<int64_t> delay_us_;
  std::vector<Flight> in_flight_;
  uint64_t sent_ = 0, last_order_ = 0, lost_ = 0, reordered_ = 0;
};

class LossyTransport final : public DeviceTransport {
 public:
  using Bytes = std::vector<uint8_t>;

  // inner must outlive this; clock is the fake clock the test drives.
  LossyTransport(DeviceTransport* inner, const LinkOptions& options, MicrosClock clock)
      : inner_(inner),
        clock_(clock),
        poses_(options, options.seed * 3 + 1),
        models_(options, options.seed * 3 + 2),
        statuses_(options, options.seed * 3 + 3) {}

  bool PublishDeviceState(const device_state_t& msg) override {
    poses_.Send(msg, clock_());
    MovePoses();
    return true;
  }
  // The device's own status is not what this link is about: straight through.
  bool PublishDeviceStatus(const device_status_t& msg) override {
    return inner_->PublishDeviceStatus(msg);
  }
  int PollForceModels(int wait_ms, const ForceModelSink& sink) override {
    MovePoses();
    const int64_t now = clock_();
    const int polled = inner_->PollForceModels(wait_ms, [&](const void* data, int size) {
      models_.Send(Bytes(static_cast<const uint8_t*>(data),
                         static_cast<const uint8_t*>(data) + size), now);
    });
    if (polled < 0) return polled;
    return models_.DeliverDue(now, [&](const Bytes& b) {
      sink(b.data(), static_cast<int>(b.size()));
    });
  }
  int PollSolverStatus(const StatusSink& sink) override {
    const int64_t now = clock_();
    inner_->PollSolverStatus([&](const void* data, int size) {
      statuses_.Send(Bytes(static_cast<const uint8_t*>(data),
                           static_cast<const uint8_t*>(data) + size), now);
    });
    return statuses_.DeliverDue(now, [&](const Bytes& b) {
      sink(b.data(), static_cast<int>(b.size()));
    });
  }

  // Poses due by now reach the inner transport (where the server fake reads them).
  void MovePoses() {
    poses_.DeliverDue(clock_(), [&](const device_state_t& s) { inner_->PublishDeviceState(s); });
  }

  const DelayLine<device_state_t>& poses() const { return poses_; }
  const DelayLine<Bytes>& models() const { return models_; }

 private:
  DeviceTransport* inner_;
  MicrosClock clock_;
  DelayLine<device_state_t> poses_;
  DelayLine<Bytes> models_;
  DelayLine<Bytes> statuses_;
};

}  // namespace snapthread::device::testing
