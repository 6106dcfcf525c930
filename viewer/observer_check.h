// What an observer (the viewer, the web bridge, their log replays) checks before it shows
// a message (docs/security.md, "Roles on the wire"). Observers hold only the server's
// public key, so everything they show is signed:
//   * shapes, solver statuses and force models: the server's Ed25519 signature (current or
//     previous key, either slot) over the bytes received, and sender_role == server;
//   * device statuses: the server's certificate of the device's public key for the
//     sender's name and key expiry, then the device's own signature with that key, and
//     sender_role == device.
// The server signs force models only at display rate: one without any signature is not
// for observers and is skipped without counting (ObserverVerdict::kUnsigned).
//
// `data`/`size` are the buffer as received (or as logged) and `decoded` its exact
// decoding (messages::DecodeAndValidate). Allocation-free after the first message of each
// size; never throws.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <type_traits>

#include "auth/key_id.h"
#include "snapthread/device_status_t.hpp"
#include "snapthread/force_model_t.hpp"

namespace snapthread::viewer {

enum class ObserverVerdict {
  kAccepted,  // genuine: show it (freshness is the caller's next check)
  kUnsigned,  // no signature at all: not meant for observers (force models between frames)
  kRefused,   // a signature or certificate that does not verify, or the wrong role: count it
};

// Whether the signature slots of an encoded message (its last 160 bytes: signature,
// signature2, mac) are both zero. False for a buffer too short to hold them.
bool SignaturesAbsent(const void* data, std::size_t size);

// A message the server signs: its signature under `server_key` and the decoded sender role
// (kUnsigned when both signature slots are zero).
ObserverVerdict CheckServerSigned(const void* data, std::size_t size, std::string_view channel,
                                  int8_t sender_role, const auth::PublicKey& server_key);

// A device status: its certificate under `server_key`, then the device's signature.
ObserverVerdict CheckDeviceStatus(const void* data, std::size_t size, std::string_view channel,
                                  const device_status_t& decoded, const auth::PublicKey& server_key);

// The check of any observed message type (device statuses by certificate, the rest as
// signed by the server). Only a force model may come unsigned; any other without a
// signature is refused.
template <class Msg>
ObserverVerdict CheckObserved(const void* data, std::size_t size, std::string_view channel,
                              const Msg& decoded, const auth::PublicKey& server_key) {
  if constexpr (std::is_same_v<Msg, device_status_t>) {
    return CheckDeviceStatus(data, size, channel, decoded, server_key);
  } else {
    const ObserverVerdict v = CheckServerSigned(data, size, channel, decoded.sender_role, server_key);
    if (v == ObserverVerdict::kUnsigned && !std::is_same_v<Msg, force_model_t>) return ObserverVerdict::kRefused;
    return v;
  }
}

}  // namespace snapthread::viewer
