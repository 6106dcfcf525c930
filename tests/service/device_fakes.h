// In-memory stand-ins for the network and the server, so a whole DeviceClient runs in
// one thread without LCM: InMemoryTransport keeps what the client publishes and hands it
// encoded force models; SpringServer answers each new pose with the force model of a
// known linear spring, echoing the pose's sequence number and time.
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

#include "snapthread/force_model_t.hpp"
#include "transport.h"

namespace snapthread::device::testing {

class InMemoryTransport final : public DeviceTransport {
 public:
  bool PublishDeviceState(const device_state_t& msg) override {
    states.push_back(msg);
    return true;
  }
  bool PublishDeviceStatus(const device_status_t& msg) override {
    statuses.push_back(msg);
    return true;
  }
  int PollForceModels(int /*wait_ms*/, const ForceModelSink& sink) override {
    const int n = static_cast<int>(inbox_.size());
    for (const auto& bytes : inbox_) sink(bytes.data(), static_cast<int>(bytes.size()));
    inbox_.clear();
    return n;
  }

  // The server side: queue bytes (a force model as it would come off the wire).
  void Deliver(std::vector<uint8_t> bytes) { inbox_.push_back(std::move(bytes)); }
  void Deliver(const force_model_t& msg) {
    std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
    msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    Deliver(std::move(bytes));
  }

  std::vector<device_state_t> states;
  std::vector<device_status_t> statuses;

 private:
  std::vector<std::vector<uint8_t>> inbox_;
};

// F(p) = -k (p - anchor), newtons, p in metres: f0 = F(u0), K = -k I, so the model is
// exact everywhere and the device must render F(p) at every pose p it is at.
class SpringServer {
 public:
  SpringServer(InMemoryTransport* transport, double k_n_per_m) : t_(transport), k_(k_n_per_m) {}

  void set_stiffness(double k_n_per_m) { k_ = k_n_per_m; }

  force_model_t ModelFor(const device_state_t& s) {
    force_model_t m{};
    m.seq = seq_++;
    m.device_seq = s.seq;
    m.device_utime = s.utime;
    m.status = force_model_t::STATUS_REGULAR;
    for (int i = 0; i < 3; ++i) {
      m.u0[i] = s.position[i];
      m.f0[i] = -k_ * (s.position[i] - anchor_m[i]);
      m.K[i][i] = -k_;
    }
    return m;
  }

  // The poses published since the last call, not yet answered.
  std::vector<device_state_t> TakeNewPoses() {
    std::vector<device_state_t> out(t_->states.begin() + static_cast<long>(taken_), t_->states.end());
    taken_ = t_->states.size();
    return out;
  }

  // Answers every new pose (latest last); returns how many.
  int AnswerAll() {
    int n = 0;
    for (const auto& s : TakeNewPoses()) {
      t_->Deliver(ModelFor(s));
      ++n;
    }
    return n;
  }

  double anchor_m[3] = {0.0, 0.0, 0.0};
  double k() const { return k_; }

 private:
  InMemoryTransport* t_;
  double k_;
  int64_t seq_ = 1;
  size_t taken_ = 0;
};

}  // namespace snapthread::device::testing
