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

#include "realtime/percentiles.h"
#include "safety.h"
#include "servo_loop.h"

namespace snapthread::device {

class ModelReceiver {
 public:
  // slot must outlive the receiver.
  ModelReceiver(const SafetyLimits& limits, ModelSlot* slot);

  // One encoded force_model_t received at now_us (device CLOCK_MONOTONIC). True when it
  // reached the servo (possibly as a zero-force model for STATUS_INVALID). Never throws.
  bool Receive(const void* data, int size, int64_t now_us);

  // Round trip pose -> answering model on the device's clock: the last ~2 s, or the run.
  transport::PercentileSummary RoundTrip(bool whole_run) const;

  uint64_t received() const { return received_.load(); }
  uint64_t rejected() const { return rejected_.load(); }
  uint64_t stiffness_clamps() const { return stiffness_clamps_.load(); }
  uint64_t invalid_models() const { return invalid_models_.load(); }
  uint64_t snaps_felt() const { return snaps_felt_.load(); }

 private:
  void Reject(const std::string& why);

  SafetyLimits limits_;
  ModelSlot* slot_;
  std::atomic<uint64_t> received_{0}, rejected_{0}, stiffness_clamps_{0}, invalid_models_{0},
      snaps_felt_{0};
  mutable std::mutex mutex_;  // the round-trip windows (receiver and status threads)
  transport::SampleWindow round_trip_window_{2000};
  transport::SampleWindow round_trip_run_{200000};
};

}  // namespace snapthread::device
