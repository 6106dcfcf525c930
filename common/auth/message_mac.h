// Tagging and checking one LCM message (docs/security.md, "Roles on the wire").
//
// Every snapthread LCM type ends with the same trailer:
//   int64_t epoch; int64_t auth_seq; int8_t sender_role; string sender_name;
//   int64_t key_expires; int64_t key_id; byte signature[64]; byte signature2[64]; byte mac[32];
// so the encoding's last 160 bytes are the two signatures and the MAC. A sender tags with
// what its role holds (a Tagger):
//   * signature, signature2: Ed25519 (crypto_sign_detached) over
//       "snapthread-sig-v1" || u32 length of the channel || channel ||
//       the encoding with signature, signature2 and mac zeroed;
//     by the server (its current key, and its previous key during a rotation's grace) for
//     what observers show, or by a device's own key for its status;
//   * mac: crypto_auth (HMAC-SHA512-256) under a device's or operator's key over
//       "snapthread-mac-v2" || u32 length of the channel || channel ||
//       the encoding with mac zeroed (the signatures in place);
// so a tag binds the type (fingerprint), every field, the sender's claimed role, name,
// expiry and key id, the epoch, the sequence number and the channel. Payloads stay in
// clear: lcm-logger, lcm-spy and the report decode them as before.
//
// Sign, VerifyMac and VerifySignature work in a per-thread buffer that grows to the largest
// message seen and is then reused: after the first message of each size they allocate
// nothing (the device signs at up to 1 kHz). None of them throws.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>

#include "auth/key_id.h"
#include "auth/role.h"
#include "auth/session_key.h"
#include "auth/signature.h"

namespace snapthread::auth {

inline constexpr std::size_t kMacBytes = 32;  // crypto_auth_BYTES
// The tags at the end of every encoding: signature, signature2, mac.
inline constexpr std::size_t kTagBytes = 2 * kSignatureBytes + kMacBytes;
// Largest message signed or checked (a 100,000-node thread_shape_t is 2.4 MB); larger
// buffers are refused rather than kept as a per-thread allocation.
inline constexpr std::size_t kMaxMacMessageBytes = 8u << 20;

// How a program tags what it publishes (the parts it has; see the header comment).
struct Tagger {
  Role role = Role::kServer;       // sender_role
  std::string name;                // sender_name
  int64_t expires_unix_s = 0;      // key_expires of mac_key's credential
  KeyId key_id{};                  // key_id: mac_key's id
  const SessionKey* mac_key = nullptr;         // -> mac (zero when null)
  const Signer* signer = nullptr;              // -> signature (zero when null)
  const Signer* previous_signer = nullptr;     // -> signature2 (zero when null)
};

// A key id as the int64 the messages carry (little-endian bytes), and back.
int64_t KeyIdToWire(const KeyId& id);
KeyId KeyIdFromWire(int64_t wire);

namespace detail {
// The calling thread's buffer: a domain prefix for `channel` followed by `message_bytes`
// free bytes for the encoded message; returns the start of the message part, or nullptr
// when the buffer cannot grow (or message_bytes exceeds kMaxMacMessageBytes).
uint8_t* PrepareTagBuffer(std::string_view channel, std::size_t message_bytes) noexcept;
// Fills the tags at the end of the encoded message in the buffer (message_bytes long,
// tags zeroed), as `tagger` can.
void ApplyTags(std::size_t message_bytes, const Tagger& tagger) noexcept;
}  // namespace detail

// Sets the trailer of `msg` for publication on `channel` and tags it with what `tagger`
// holds. False (and every tag zeroed) when LCM cannot encode the message consistently
// (e.g. a string with an embedded NUL): such a message must not be published.
template <class Msg>
[[nodiscard]] bool Sign(Msg* msg, std::string_view channel, int64_t epoch, int64_t auth_seq,
                        const Tagger& tagger) {
  static_assert(std::is_same_v<decltype(msg->mac), uint8_t[kMacBytes]>,
                "the message type must end with the authentication trailer");
  msg->epoch = epoch;
  msg->auth_seq = auth_seq;
  msg->sender_role = static_cast<int8_t>(tagger.role);
  msg->sender_name.assign(tagger.name);  // reuses the capacity of a same-length name
  const bool has_mac = tagger.mac_key != nullptr;
  msg->key_expires = has_mac ? tagger.expires_unix_s : 0;
  msg->key_id = has_mac ? KeyIdToWire(tagger.key_id) : 0;
  std::memset(msg->signature, 0, sizeof msg->signature);
  std::memset(msg->signature2, 0, sizeof msg->signature2);
  std::memset(msg->mac, 0, sizeof msg->mac);
  const int size = msg->getEncodedSize();
  if (size <= 0) return false;
  uint8_t* bytes = detail::PrepareTagBuffer(channel, static_cast<std::size_t>(size));
  if (bytes == nullptr) return false;
  if (msg->encode(bytes, 0, size) != size) return false;
  detail::ApplyTags(static_cast<std::size_t>(size), tagger);
  const uint8_t* tags = bytes + size - kTagBytes;
  std::memcpy(msg->signature, tags, kSignatureBytes);
  std::memcpy(msg->signature2, tags + kSignatureBytes, kSignatureBytes);
  std::memcpy(msg->mac, tags + 2 * kSignatureBytes, kMacBytes);
  return true;
}

// Checks a received LCM buffer (what the subscriber got) in constant time
// (crypto_auth_verify): the MAC is the buffer's last 32 bytes; every other byte is
// covered, so any change to any byte is refused. A zero MAC is refused. Use it together
// with an exact decode (no trailing bytes).
[[nodiscard]] bool VerifyMac(const void* data, std::size_t size, std::string_view channel,
                             const SessionKey& key);

// Whether `signature` or `signature2` of the received buffer is `key`'s signature of it
// (crypto_sign_verify_detached). Zero slots are skipped without a verification.
[[nodiscard]] bool VerifySignature(const void* data, std::size_t size, std::string_view channel,
                                   const PublicKey& key);

// A MAC with the root key itself, as before the roles (tests of what the server refuses:
// no role resolves such a key). Programs tag with KeySet's taggers.
inline Tagger RootMacTagger(const SessionKey& root) {
  Tagger t;
  t.mac_key = &root;  // key_id stays zero: nothing resolves it (and RootKeyId allocates)
  return t;
}

}  // namespace snapthread::auth
