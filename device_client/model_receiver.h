// ModelReceiver: the receiving half of the device client, off the servo thread. Each
// encoded force_model_t is decoded and validated (messages/validate.h: the one force
// model check), prepared for the servo (PrepareModel: stiffness clamp, STATUS_INVALID ->
// zero force) and handed to the servo thread through a LatestValue (wait-free for the
// reader). Everything refused is counted and never reaches the device.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

#include "auth/freshness_filter.h"
#include "auth/pose_echo_window.h"
#include "device_keys.h"
#include "local_model.h"
#include "model_order.h"
#include "realtime/percentiles.h"
#include "servo_loop.h"
#include "snapthread/force_model_t.hpp"

namespace snapthread::device {

// What the receiver checks when the session is authenticated (docs/security.md, "Roles
// on the wire"): force models MACed by the server under this device's key (or its
// previous key during a reload's grace), solver statuses signed by the server.
struct ModelAuth {
  const DeviceKeys* keys = nullptr;       // nullptr: no checks (in-process tests only)
  std::string force_model_channel;        // <SESSION>_FORCE_MODEL
  std::string status_channel;             // <SESSION>_SOLVER_STATUS
  const auth::PoseEchoWindow* sent = nullptr;  // the poses this device sent
};

class ModelReceiver {
 public:
  // slot (and auth's key and window) must outlive the receiver.
  ModelReceiver(const SafetyLimits& limits, ModelSlot* slot, ModelAuth auth = {});

  // One encoded solver_status_t received at now_us: with the server's signature (of the
  // credential's server key, or the previous credential's during its grace) and a fresh
  // (epoch, auth_seq) its epoch becomes the one force models must carry (FreshnessFilter
  // kAdopt). Same thread as Receive. Never throws.
  bool ReceiveStatus(const void* data, int size, int64_t now_us);
  // The grasp this device holds. A model addressed to another device (sender_name) for
  // another grasp is another hand's: passed over, counted in other_grasp(), not rejected
  // (on a session with two hands every other model is the other hand's, and this device
  // cannot check another device's MAC). One addressed to another device for this grasp,
  // or not from the server, or with a MAC that is not this device's, is rejected. Call
  // before the first Receive.
  void SetGrasp(std::string grasp) { grasp_ = std::move(grasp); }
  uint64_t other_grasp() const { return other_grasp_.load(); }
  // The server epoch learned from an authenticated status; 0 until one was heard.
  int64_t epoch() const { return status_filter_.epoch(); }
  uint64_t statuses_rejected() const { return status_filter_.rejected(); }
  uint64_t statuses_accepted() const { return status_filter_.accepted(); }

  // One encoded force_model_t received at now_us (device CLOCK_MONOTONIC). True when it
  // reached the servo (possibly as a zero-force model for STATUS_INVALID). Never throws.
  bool Receive(const void* data, int size, int64_t now_us);

  // Round trip pose -> answering model on the device's clock: the last ~2 s, or the run.
  realtime::PercentileSummary RoundTrip(bool whole_run) const;

  uint64_t received() const { return received_.load(); }
  // Malformed or unsafe models, those refused by authentication and those older than
  // the applied one (ModelOrder).
  uint64_t rejected() const {
    return rejected_.load() + model_filter_.rejected() + sender_rejected_.load() + out_of_order_.load();
  }
  // Models dropped because a newer one was already applied (reordering on the network).
  uint64_t out_of_order() const { return out_of_order_.load(); }
  uint64_t auth_rejected() const { return model_filter_.rejected() + sender_rejected_.load(); }
  // Models refused for their sender: not the server's (sender_role), or addressed to
  // another device for this grasp (sender_name). Part of auth_rejected() and rejected().
  uint64_t sender_rejected() const { return sender_rejected_.load(); }
  const auth::FreshnessFilter& model_filter() const { return model_filter_; }
  uint64_t stiffness_clamps() const { return stiffness_clamps_.load(); }
  uint64_t invalid_models() const { return invalid_models_.load(); }
  uint64_t snaps_felt() const { return snaps_felt_.load(); }
  // Accepted models with a 6-DoF wrench (force_model_t.has_wrench: a rod's grasp).
  uint64_t wrench_models() const { return wrench_models_.load(); }

 private:
  void Reject(const std::string& why);
  void LogAuth(auth::FreshnessFilter* filter, int64_t now_us);
  void RejectSender(const char* why, const force_model_t& msg);
  // The MAC and sender checks of an authenticated session (Receive): true to go on;
  // false when the model is refused or another hand's (counted).
  bool CheckSender(const void* data, int size, const force_model_t& msg, int64_t now_us);

  SafetyLimits limits_;
  ModelSlot* slot_;
  ModelAuth auth_;
  std::string grasp_;
  ModelOrder order_;  // receive thread only
  auth::FreshnessFilter status_filter_{"SOLVER_STATUS",
                                       auth::FreshnessFilter::EpochPolicy::kAdopt};
  auth::FreshnessFilter model_filter_{"FORCE_MODEL"};
  std::atomic<uint64_t> received_{0}, rejected_{0}, stiffness_clamps_{0}, invalid_models_{0},
      snaps_felt_{0}, out_of_order_{0}, other_grasp_{0}, wrench_models_{0}, sender_rejected_{0};
  mutable std::mutex mutex_;  // the round-trip windows (receiver and status threads)
  realtime::SampleWindow round_trip_window_{2000};
  realtime::SampleWindow round_trip_run_{200000};
};

}  // namespace snapthread::device
