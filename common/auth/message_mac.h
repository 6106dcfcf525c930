// Signing and checking one LCM message (docs/security.md).
//
// Every snapthread LCM type ends with `int64_t epoch; int64_t auth_seq; byte mac[32];`.
// The tag is libsodium's crypto_auth (HMAC-SHA512-256) under the session key over
//   "snapthread-mac-v1" || u32 length of the channel name || channel name ||
//   the LCM encoding of the message (type fingerprint included) with mac zeroed,
// so a tag binds the type, every field, the epoch, the sequence number and the channel
// (a pose signed for one grasp's channel is refused on another's). Payloads stay in
// clear: lcm-logger, lcm-spy and the report decode them as before.
//
// Sign and VerifyEncoded work in a per-thread buffer that grows to the largest message
// seen and is then reused: after the first message of each size they allocate nothing
// (the device signs at up to 1 kHz).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <type_traits>

#include "auth/session_key.h"

namespace snapthread::auth {

inline constexpr std::size_t kMacBytes = 32;  // crypto_auth_BYTES
// Largest message signed or checked (a 100,000-node thread_shape_t is 2.4 MB); larger
// buffers are refused rather than kept as a per-thread allocation.
inline constexpr std::size_t kMaxMacMessageBytes = 8u << 20;

namespace detail {
// The calling thread's buffer: the MAC prefix for `channel` followed by `message_bytes`
// free bytes for the encoded message; returns the start of the message part, or nullptr
// when the buffer cannot grow (or message_bytes exceeds kMaxMacMessageBytes).
uint8_t* PrepareMacBuffer(std::string_view channel, std::size_t message_bytes) noexcept;
// Tag over the prefix and the first `message_bytes` bytes of the message part.
void ComputeMac(std::size_t message_bytes, const SessionKey& key, uint8_t tag[kMacBytes]);
}  // namespace detail

// Sets msg->epoch, msg->auth_seq and msg->mac for publication on `channel`. False (and
// mac zeroed) when LCM cannot encode the message consistently (e.g. a string with an
// embedded NUL): such a message must not be published. Never throws.
template <class Msg>
[[nodiscard]] bool Sign(Msg* msg, std::string_view channel, int64_t epoch, int64_t auth_seq,
                        const SessionKey& key) {
  static_assert(std::is_same_v<decltype(msg->mac), uint8_t[kMacBytes]>,
                "the message type must end with `byte mac[32]`");
  msg->epoch = epoch;
  msg->auth_seq = auth_seq;
  for (auto& b : msg->mac) b = 0;
  const int size = msg->getEncodedSize();
  if (size <= 0) return false;
  uint8_t* bytes = detail::PrepareMacBuffer(channel, static_cast<std::size_t>(size));
  if (bytes == nullptr) return false;
  if (msg->encode(bytes, 0, size) != size) return false;
  detail::ComputeMac(static_cast<std::size_t>(size), key, msg->mac);
  return true;
}

// Checks a received LCM buffer (what the subscriber got, before or after decoding) in
// constant time (crypto_auth_verify). The tag is the buffer's last 32 bytes, where
// `byte mac[32]` is encoded; every other byte is covered, so any change to any byte is
// refused. Use it together with an exact decode (no trailing bytes). Never throws.
[[nodiscard]] bool VerifyEncoded(const void* data, std::size_t size, std::string_view channel,
                                 const SessionKey& key);

}  // namespace snapthread::auth
