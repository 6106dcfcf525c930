#include "model_receiver.h"

#include <spdlog/spdlog.h>

#include "messages/validate.h"
#include "snapthread/force_model_t.hpp"

namespace snapthread::device {

ModelReceiver::ModelReceiver(const SafetyLimits& limits, ModelSlot* slot)
    : limits_(limits), slot_(slot) {}

bool ModelReceiver::Receive(const void* data, int size, int64_t now_us) {
  try {
    force_model_t msg;
    std::string why;
    if (!transport::DecodeAndValidate(data, size, &msg, &why)) {
      Reject(why);
      return false;
    }
    LocalModel model;
    const ModelVerdict verdict = PrepareModel(msg, now_us, limits_, &model, &why);
    if (verdict == ModelVerdict::kRejected) {
      Reject(why);
      return false;
    }
    if (verdict == ModelVerdict::kStiffnessClamped) stiffness_clamps_.fetch_add(1);
    if (verdict == ModelVerdict::kInvalidStatus) invalid_models_.fetch_add(1);
    if (msg.status == force_model_t::STATUS_SNAPPED) snaps_felt_.fetch_add(1);
    slot_->Write(model);
    received_.fetch_add(1);
    // Round trip on the device's own clock: pose time echoed back by the server.
    const int64_t rt = now_us - msg.device_utime;
    if (msg.device_utime > 0 && rt >= 0 && rt < 10000000) {
      std::lock_guard<std::mutex> lock(mutex_);
      round_trip_window_.Push(static_cast<double>(rt));
      round_trip_run_.Push(static_cast<double>(rt));
    }
    return true;
  } catch (...) {
    rejected_.fetch_add(1);
    return false;
  }
}

transport::PercentileSummary ModelReceiver::RoundTrip(bool whole_run) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return whole_run ? round_trip_run_.Compute() : round_trip_window_.Compute();
}

void ModelReceiver::Reject(const std::string& why) {
  const uint64_t n = rejected_.fetch_add(1) + 1;
  // Rate-limited: a flood of garbage must not become a flood of log lines.
  if (n <= 5 || n % 1000 == 0) {
    spdlog::warn("device: force model rejected ({} so far): {}", n, why);
  }
}

}  // namespace snapthread::device
