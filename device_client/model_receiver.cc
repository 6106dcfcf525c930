#include "model_receiver.h"

#include <spdlog/spdlog.h>

#include <utility>

#include "auth/message_mac.h"
#include "auth/message_gate.h"
#include "auth/role.h"
#include "messages/validate.h"
#include "realtime/clock.h"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"

namespace snapthread::device {

ModelReceiver::ModelReceiver(const SafetyLimits& limits, ModelSlot* slot, ModelAuth auth)
    : limits_(limits), slot_(slot), auth_(std::move(auth)), order_(auth_.keys == nullptr) {}

void ModelReceiver::LogAuth(auth::FreshnessFilter* filter, int64_t now_us) {
  std::string line;
  if (filter->TakeLogLine(now_us, &line)) spdlog::warn("device: refused {}", line);
}

bool ModelReceiver::ReceiveStatus(const void* data, int size, int64_t now_us) {
  if (auth_.keys == nullptr) return false;
  try {
    solver_status_t msg;
    std::string why;
    if (!messages::DecodeAndValidate(data, size, &msg, &why)) return false;
    const int64_t before = status_filter_.epoch();
    const auto n = static_cast<size_t>(size);
    const auth::KeySet* previous = auth_.keys->Previous(now_us);
    const bool signed_by_server =
        auth::VerifySignature(data, n, auth_.status_channel, auth_.keys->current().server_public_key()) ||
        (previous != nullptr &&
         auth::VerifySignature(data, n, auth_.status_channel, previous->server_public_key()));
    if (!signed_by_server) status_filter_.Reject(auth::Reason::kBadMac);
    if (!signed_by_server || status_filter_.Admit(msg.epoch, msg.auth_seq) != auth::Reason::kAccepted) {
      LogAuth(&status_filter_, now_us);
      return false;
    }
    if (status_filter_.epoch() != before) {
      spdlog::info("device: server session epoch {:016x} (from an authenticated status)",
                   static_cast<uint64_t>(status_filter_.epoch()));
    }
    return true;
  } catch (...) {
    return false;
  }
}

bool ModelReceiver::Receive(const void* data, int size, int64_t now_us) {
  try {
    force_model_t msg;
    std::string why;
    if (!messages::DecodeAndValidate(data, size, &msg, &why)) {
      Reject(why);
      return false;
    }
    if (auth_.keys != nullptr && !CheckSender(data, size, msg, now_us)) return false;
    // Another hand's model: it answers that device's poses, never this one's.
    if (msg.grasp != grasp_) {
      other_grasp_.fetch_add(1);
      return false;
    }
    if (auth_.keys != nullptr) {
      // Models must carry the epoch learned from the server's status (0: none yet, so
      // everything is refused and the device stays in its fade).
      const int64_t epoch = status_filter_.epoch();
      if (epoch != model_filter_.epoch()) model_filter_.SetEpoch(epoch);
      if (auth::AdmitVerifiedForceModel(msg, *auth_.sent, &model_filter_) !=
          auth::Reason::kAccepted) {
        LogAuth(&model_filter_, now_us);
        return false;
      }
    }
    // Never an older model after a newer one. Counted apart (part of models_rejected, as
    // the signed session's stale auth_seq is) and not logged: reordering is what a lossy
    // network does, not an attack.
    if (!order_.IsNewer(msg.epoch, msg.seq, msg.device_seq)) {
      out_of_order_.fetch_add(1);
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
    if (model.has_wrench) wrench_models_.fetch_add(1);
    slot_->Write(model);
    order_.Applied(msg.epoch, msg.seq, msg.device_seq);
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

bool ModelReceiver::CheckSender(const void* data, int size, const force_model_t& msg, int64_t now_us) {
  if (msg.sender_role != static_cast<int8_t>(auth::Role::kServer)) {
    RejectSender("not from the server (sender_role)", msg);
    return false;
  }
  if (msg.sender_name != auth_.keys->name()) {
    // Another device's model: another hand's when it is for another grasp.
    if (msg.grasp != grasp_) {
      other_grasp_.fetch_add(1);
    } else {
      RejectSender("addressed to another device (sender_name)", msg);
    }
    return false;
  }
  // This device's key (or its previous one during a reload's grace), named by key_id;
  // the MAC covers key_id, so a forged one only picks the key that refuses it.
  const auth::KeySet* keys = auth_.keys->ForKeyId(msg.key_id, now_us);
  if (keys == nullptr || !auth::VerifyMac(data, static_cast<size_t>(size), auth_.force_model_channel,
                                          *keys->mac_key())) {
    model_filter_.Reject(auth::Reason::kBadMac);
    LogAuth(&model_filter_, now_us);
    return false;
  }
  return true;
}

void ModelReceiver::RejectSender(const char* why, const force_model_t& msg) {
  const uint64_t n = sender_rejected_.fetch_add(1) + 1;
  // Rate-limited as Reject: a flood must not become a flood of log lines.
  if (n <= 5 || n % 1000 == 0) {
    spdlog::warn("device: refused FORCE_MODEL ({} so far for its sender): {}: role {}, name '{}'", n, why,
                 static_cast<int>(msg.sender_role), msg.sender_name);
  }
}

realtime::PercentileSummary ModelReceiver::RoundTrip(bool whole_run) const {
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
