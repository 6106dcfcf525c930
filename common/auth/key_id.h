// Key ids: 8 bytes that name a key in a message, a credential file or a revocation list
// without revealing it, and the hex form they are written in.
//
// A symmetric key's id is a BLAKE2b hash keyed with the key itself over a domain label
// ("snapthread-key-id-v1 device", ...), so it is a PRF output that shows nothing about the
// key and differs between roles even for equal bytes. A public key's id is an unkeyed
// BLAKE2b of a label and the public key. The root key's id is SessionKey::Id(), the id
// snapthread-keygen --id has always printed.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "auth/session_key.h"

namespace snapthread::auth {

inline constexpr std::size_t kKeyIdBytes = 8;
using KeyId = std::array<uint8_t, kKeyIdBytes>;

inline constexpr std::size_t kPublicKeyBytes = 32;  // crypto_sign_PUBLICKEYBYTES (Ed25519)
using PublicKey = std::array<uint8_t, kPublicKeyBytes>;

// Id of a symmetric key under a domain label (e.g. "device", "operator", "read").
KeyId SecretKeyId(std::string_view label, const SessionKey& key);
// The same from raw key bytes (SessionKey::kBytes of them); allocates nothing.
KeyId SecretKeyId(std::string_view label, const uint8_t* key_bytes);
// Id of an Ed25519 public key.
KeyId PublicKeyId(const PublicKey& key);
// Id of the root key: the bytes of SessionKey::Id().
KeyId RootKeyId(const SessionKey& root);

// Lower-case hex, two digits a byte.
std::string ToHex(const uint8_t* bytes, std::size_t size);
std::string KeyIdToHex(const KeyId& id);
// Exactly 2 * size hex digits (either case) into `out`; false otherwise (nothing else is
// accepted: no spaces, no prefix).
[[nodiscard]] bool FromHex(std::string_view hex, uint8_t* out, std::size_t size);
std::optional<KeyId> KeyIdFromHex(std::string_view hex);

}  // namespace snapthread::auth
