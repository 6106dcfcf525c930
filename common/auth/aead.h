// Sealed payloads for the optional privacy of a session (docs/security.md, "Roles: the
// key hierarchy"): XChaCha20-Poly1305 (crypto_aead_xchacha20poly1305_ietf) under a role's
// key: the observers' read key for what the server publishes, a device's seal key
// (DeriveDeviceSealKey) for its traffic with the server.
//
// A sealed buffer is  nonce (24 random bytes) || ciphertext || tag (16 bytes), so its size
// is the plaintext's plus kAeadOverheadBytes. The associated data (e.g. the channel name
// and the key id) is authenticated, not sent: Open with other associated data fails. A
// 24-byte random nonce never repeats in practice (2^96 messages for a 2^-32 chance), so
// senders need no counter. Sealing gives confidentiality among the key's holders, not
// authorship: every holder of a read key could seal; who made a message is told by its
// MAC or signature, which the sender computes over the sealed bytes.
//
// Seal and Open write into the caller's buffers: they allocate nothing and never throw.
#pragma once

#include <cstddef>
#include <cstdint>

#include "auth/session_key.h"

namespace snapthread::auth {

inline constexpr std::size_t kAeadNonceBytes = 24;  // crypto_aead_xchacha20poly1305_ietf_NPUBBYTES
inline constexpr std::size_t kAeadTagBytes = 16;    // crypto_aead_xchacha20poly1305_ietf_ABYTES
inline constexpr std::size_t kAeadOverheadBytes = kAeadNonceBytes + kAeadTagBytes;

struct ByteView {
  const uint8_t* data = nullptr;
  std::size_t size = 0;
};

// Seals `plain` into `out` (capacity `out_capacity`, at least plain.size +
// kAeadOverheadBytes) with a fresh random nonce; *out_size is the sealed size. False (and
// *out_size 0) when `out` is too small.
[[nodiscard]] bool Seal(const SessionKey& key, ByteView plain, ByteView associated, uint8_t* out,
                        std::size_t out_capacity, std::size_t* out_size) noexcept;

// Opens a sealed buffer into `plain_out` (capacity at least sealed.size -
// kAeadOverheadBytes); *plain_size is the plaintext's size. False (and *plain_size 0, the
// output wiped) when the buffer is too short, `plain_out` too small, or the key, the
// associated data or any byte differ from the sealing.
[[nodiscard]] bool Open(const SessionKey& key, ByteView sealed, ByteView associated,
                        uint8_t* plain_out, std::size_t plain_capacity,
                        std::size_t* plain_size) noexcept;

}  // namespace snapthread::auth
