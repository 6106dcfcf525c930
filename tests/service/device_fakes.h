// In-memory stand-ins for the network and the server, so a whole DeviceClient runs in
// one thread without LCM: InMemoryTransport keeps what the client publishes and hands it
// encoded force models; SpringServer answers each new pose with the force model of a
// known linear spring, echoing the pose's sequence number and time (optionally with one
// snap, and tagged as the real server does: force models MACed with the device's key,
// sender_role server, sender_name the device; solver statuses signed by the server).
#pragma once

#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/role.h"
#include "auth/session_epoch.h"
#include "auth/session_key.h"
#include "device_keys.h"
#include "messages/channels.h"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "transport.h"

namespace snapthread::device::testing {

// An LCM message as it comes off the wire.
template <class Msg>
std::vector<uint8_t> Encoded(const Msg& msg) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// The device name snapthread-device takes on the root key when its poses name no grasp.
inline constexpr const char* kDefaultDeviceName = "hand";

// Device `name`'s keys issued from `root` (what the device client is given), with a
// reload grace of grace_us.
inline std::unique_ptr<DeviceKeys> DeviceKeysFor(const auth::SessionKey& root,
                                                 const std::string& name = kDefaultDeviceName,
                                                 int64_t grace_us = 60000000) {
  return std::make_unique<DeviceKeys>(auth::KeySet::ForRole(root, auth::Role::kDevice, name), grace_us);
}

// How the server tags a force model for the device whose keys are `device` (no signature:
// the server signs models at display rate only).
inline auth::Tagger ForceModelTagger(const auth::KeySet& device) { return device.ForceModelTagger(); }

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

  int PollSolverStatus(const StatusSink& sink) override {
    const int n = static_cast<int>(status_inbox_.size());
    for (const auto& bytes : status_inbox_) sink(bytes.data(), static_cast<int>(bytes.size()));
    status_inbox_.clear();
    return n;
  }
  // A solver_status_t as it would come off the wire.
  void DeliverStatus(std::vector<uint8_t> bytes) { status_inbox_.push_back(std::move(bytes)); }

  // The server side: queue bytes (a force model as it would come off the wire).
  void Deliver(std::vector<uint8_t> bytes) { inbox_.push_back(std::move(bytes)); }
  void Deliver(const force_model_t& msg) { Deliver(Encoded(msg)); }

  std::vector<device_state_t> states;
  std::vector<device_status_t> statuses;

 private:
  std::vector<std::vector<uint8_t>> inbox_;
  std::vector<std::vector<uint8_t>> status_inbox_;
};

// F(p) = -k (p - anchor), newtons, p in metres: f0 = F(u0), K = -k I, so the model is
// exact everywhere and the device must render F(p) at every pose p it is at.
class SpringServer {
 public:
  SpringServer(InMemoryTransport* transport, double k_n_per_m) : t_(transport), k_(k_n_per_m) {}

  void set_stiffness(double k_n_per_m) { k_ = k_n_per_m; }

  // Tags every model AnswerAll sends (MAC with device `device_name`'s key issued from
  // `root`), and signs DeliverStatus (the server key of `root`), for `session`: the device
  // then learns `epoch` and checks as in production.
  void SignWith(const auth::SessionKey* root, int64_t epoch, const std::string& session,
                const std::string& device_name = kDefaultDeviceName) {
    server_keys_ = std::make_unique<auth::KeySet>(auth::KeySet::ForRole(*root, auth::Role::kServer));
    MacWith(auth::KeySet::ForRole(*root, auth::Role::kDevice, device_name));
    epoch_ = epoch;
    channels_ = messages::Channels(session);
  }
  // From now on, MACs models with `device`'s key (a rotation: the server's new key for the
  // device, or another device's key for a forger).
  void MacWith(auth::KeySet device) {
    device_keys_ = std::make_unique<auth::KeySet>(std::move(device));
    model_tagger_ = ForceModelTagger(*device_keys_);
  }
  // Tags models as `tagger` says instead (a forger: another role, no MAC...).
  void TagModelsWith(const auth::Tagger& tagger) { model_tagger_ = tagger; }

  force_model_t ModelFor(const device_state_t& s) {
    force_model_t m{};
    m.seq = seq_++;
    m.device_seq = s.seq;
    m.device_utime = s.utime;
    // The snaps, with hysteresis as a fold pair has: a pose at or past snap_at_x_m moves
    // the thread to its other branch, one at or below snap_back_at_x_m moves it back.
    const bool snaps_now = snapped_ ? s.position[0] <= snap_back_at_x_m
                                    : s.position[0] >= snap_at_x_m;
    if (snaps_now) {
      snapped_ = !snapped_;
      ++snaps_;
    }
    m.status = snaps_now ? force_model_t::STATUS_SNAPPED : force_model_t::STATUS_REGULAR;
    for (int i = 0; i < 3; ++i) {
      m.u0[i] = s.position[i];
      m.f0[i] = -k_ * (s.position[i] - anchor_m[i]) + (snapped_ ? snap_jump_n[i] : 0.0);
      m.K[i][i] = -k_;
    }
    return m;
  }

  // A signed solver status announcing the epoch (SignWith first).
  void DeliverStatus() {
    solver_status_t st{};
    st.scene = "spring";
    st.method = "spring";
    if (server_keys_ != nullptr &&
        auth::Sign(&st, channels_.solver_status, epoch_, auth_seq_.Next(), server_keys_->tagger())) {
      t_->DeliverStatus(Encoded(st));
    }
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
    for (const auto& s : TakeNewPoses()) n += Send(ModelFor(s)) ? 1 : 0;
    return n;
  }

  // Sends a model (signed with this server's epoch after SignWith); false when it
  // cannot be signed.
  bool Send(force_model_t m) {
    if (server_keys_ != nullptr &&
        !auth::Sign(&m, channels_.force_model, epoch_, auth_seq_.Next(), model_tagger_)) {
      return false;
    }
    t_->Deliver(m);
    return true;
  }

  double anchor_m[3] = {0.0, 0.0, 0.0};
  // No snap by default; snap_jump_n is added to the force on the other branch.
  double snap_at_x_m = std::numeric_limits<double>::infinity();
  double snap_back_at_x_m = -std::numeric_limits<double>::infinity();
  double snap_jump_n[3] = {0.0, 0.0, 0.0};
  int snaps() const { return snaps_; }
  double k() const { return k_; }

 private:
  InMemoryTransport* t_;
  double k_;
  int64_t seq_ = 1;
  size_t taken_ = 0;
  bool snapped_ = false;
  int snaps_ = 0;
  std::unique_ptr<auth::KeySet> server_keys_;  // null: nothing is tagged
  std::unique_ptr<auth::KeySet> device_keys_;
  auth::Tagger model_tagger_;
  int64_t epoch_ = 0;
  auth::AuthSequence auth_seq_{0};
  messages::Channels channels_{messages::kDefaultSession};
};

}  // namespace snapthread::device::testing
