// What a receiver does with each tagged message (docs/security.md, "Roles on the wire"):
// the tag over the received bytes first (a MAC under the sender's key on the channels a
// device or an operator speaks, and on force models; the server's signature on what
// observers show), then the freshness of the decoded epoch and auth_seq, and for a force
// model on the device the echo of a pose it sent. Which key a MAC must verify under
// (KeyRing::Resolve on the server, the device's own key on the device) is the caller's
// choice: these helpers check the bytes against the key given. Each refusal is counted in the
// filter; the caller adds filter.rejected() to its status counter (models_rejected,
// rejected_messages), logs filter.TakeLogLine() and never uses a refused message.
//
// `data`/`size` are the received LCM buffer (rbuf->data, rbuf->data_size) and `decoded`
// its exact decoding (no trailing bytes; messages::DecodeAndValidate). Allocation-free
// after the first message of each size; never throws.
#pragma once

#include <cstddef>
#include <string_view>

#include "auth/freshness_filter.h"
#include "auth/message_mac.h"
#include "auth/pose_echo_window.h"
#include "auth/role.h"
#include "auth/session_key.h"
#include "auth/signature.h"
#include "snapthread/force_model_t.hpp"

namespace snapthread::auth {

// A MAC-checked message: its MAC under `key`, then its freshness.
template <class Msg>
Reason Admit(const void* data, std::size_t size, const Msg& decoded, std::string_view channel,
             const SessionKey& key, FreshnessFilter* filter) {
  if (!VerifyMac(data, size, channel, key)) {
    filter->Reject(Reason::kBadMac);
    return Reason::kBadMac;
  }
  return filter->Admit(decoded.epoch, decoded.auth_seq);
}

// A message the server signs (shape, statuses, command replies): it claims the server's
// role and `server` signed it (either signature slot), then its freshness. A failed
// signature counts as kBadMac (the tag does not verify).
template <class Msg>
Reason AdmitSigned(const void* data, std::size_t size, const Msg& decoded, std::string_view channel,
                   const PublicKey& server, FreshnessFilter* filter) {
  if (decoded.sender_role != static_cast<int8_t>(Role::kServer) ||
      !VerifySignature(data, size, channel, server)) {
    filter->Reject(Reason::kBadMac);
    return Reason::kBadMac;
  }
  return filter->Admit(decoded.epoch, decoded.auth_seq);
}

// The device's check of a force model whose MAC has already passed (VerifyMac, e.g.
// so that a forged model's grasp name is never read): its freshness, then the echo of the
// (epoch, device_seq, device_utime) of a pose in `sent`. A model refused for its echo does
// not raise the sequence floor.
inline Reason AdmitVerifiedForceModel(const force_model_t& decoded, const PoseEchoWindow& sent,
                                      FreshnessFilter* filter) {
  const Reason fresh = filter->Check(decoded.epoch, decoded.auth_seq);
  if (fresh != Reason::kAccepted) {
    filter->Reject(fresh);
    return fresh;
  }
  if (!sent.Contains(decoded.epoch, decoded.device_seq, decoded.device_utime)) {
    filter->Reject(Reason::kUnsentPoseEcho);
    return Reason::kUnsentPoseEcho;
  }
  return filter->Admit(decoded.epoch, decoded.auth_seq);
}

// The device's whole check of a force model: the MAC, then AdmitVerifiedForceModel.
inline Reason AdmitForceModel(const void* data, std::size_t size, const force_model_t& decoded,
                              std::string_view channel, const SessionKey& key,
                              const PoseEchoWindow& sent, FreshnessFilter* filter) {
  if (!VerifyMac(data, size, channel, key)) {
    filter->Reject(Reason::kBadMac);
    return Reason::kBadMac;
  }
  return AdmitVerifiedForceModel(decoded, sent, filter);
}

}  // namespace snapthread::auth
