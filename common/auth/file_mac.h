// Integrity and origin of a file the session stores (the server's checkpoint,
// server/checkpoint.h; docs/security.md "Checkpoints"): an unkeyed checksum that tells
// accidental damage (a torn or flipped byte) from a file that is intact but was not
// written by a holder of the session key (the keyed MAC).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "auth/session_key.h"

namespace snapthread::auth {

inline constexpr std::size_t kFileChecksumBytes = 32;  // BLAKE2b-256
inline constexpr std::size_t kFileMacBytes = 32;       // crypto_auth_BYTES (HMAC-SHA512-256)

// BLAKE2b-256 (libsodium crypto_generichash, no key) of data[0, size).
void FileChecksum(const void* data, std::size_t size, uint8_t out[kFileChecksumBytes]);

// crypto_auth (HMAC-SHA512-256) under the session key over
//   "snapthread-file-v1" || u32 length of `domain` || domain || data,
// so a tag made for one kind of file (domain, e.g. "checkpoint") is refused for another,
// and never equals a message tag (message_mac.h uses another prefix).
void FileMac(std::string_view domain, const void* data, std::size_t size, const SessionKey& key,
             uint8_t tag[kFileMacBytes]);
// Checks such a tag in constant time.
[[nodiscard]] bool VerifyFileMac(std::string_view domain, const void* data, std::size_t size,
                                 const SessionKey& key, const uint8_t tag[kFileMacBytes]);

}  // namespace snapthread::auth
