// Sealed messages: the optional privacy of a session (docs/security.md, "Sealed
// payloads"). A program run with --encrypt publishes, instead of each tagged message, a
// sealed_t on the same channel holding the message's encoding under XChaCha20-Poly1305
// (auth/aead.h) with the session's read key, which every credential carries; receivers
// that hold it open the envelope and check the message inside exactly as one received in
// clear (its MAC or signatures). A sniffer without a credential sees no pose, force,
// scene name or channel payload; lcm-logger records the envelopes, and the review tools
// open them given any credential of the session.
//
// The keys are process-wide (one session per program), set once at start-up and replaced
// on a reload; readers take them without a lock. During a root rotation's grace a program
// also opens with its previous read key, and the server seals with the previous one so
// that receivers not yet reloaded keep reading. Sealing and opening work in per-thread
// buffers reused after the first message of each size: allocation-free in steady state.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "auth/aead.h"
#include "auth/session_key.h"

namespace snapthread::auth {

// The process's read keys. `seal_outgoing`: --encrypt. `seal_with_previous`: seal with
// `previous` (the server during a rotation's grace). Copies the keys.
void SetSealing(const SessionKey& read_key, const SessionKey* previous, bool seal_outgoing,
                bool seal_with_previous = false);
// Forgets the keys (tests): nothing is sealed or opened after it.
void ClearSealing();
// Whether this process seals what it publishes.
bool SealingOutgoing() noexcept;

// What to publish for a tagged encoding on `channel`: a sealed_t envelope (in the calling
// thread's buffer, valid until its next call) when the process seals, else `encoded`
// itself. {nullptr, 0} when the envelope cannot be made (too large): publish nothing.
ByteView SealForChannel(ByteView encoded, std::string_view channel) noexcept;

// Whether a received buffer is a sealed_t (its type fingerprint).
bool IsSealed(const void* data, std::size_t size) noexcept;

// The message inside a sealed_t received on `channel`, opened with the process's read
// key (or its previous one) into the calling thread's buffer (valid until its next call);
// nullopt when it is malformed, sealed under another key or for another channel, or
// altered, or when the process holds no read key.
std::optional<ByteView> OpenSealed(const void* data, std::size_t size, std::string_view channel) noexcept;

// The same with an explicit key (the review tools reading a log).
std::optional<ByteView> OpenSealedWith(const SessionKey& read_key, const void* data, std::size_t size,
                                       std::string_view channel) noexcept;

}  // namespace snapthread::auth
