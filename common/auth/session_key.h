// The session key: 32 random bytes shared by every binary of one session (docs/security.md).
// Held in libsodium's guarded heap (sodium_malloc: guard pages, mlock'ed so it is not
// swapped out, read-only once filled, wiped by sodium_free), never copied.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace snapthread::auth {

// Initialises libsodium once (thread-safe, idempotent). Throws std::runtime_error when the
// library cannot start (no usable random source): nothing can be signed then.
void InitSodium();

class SessionKey {
 public:
  static constexpr std::size_t kBytes = 32;  // crypto_auth_KEYBYTES

  // A new key from the system's random source (randombytes_buf).
  static SessionKey Generate();
  // A key from kBytes bytes (a key file's content); throws std::invalid_argument on
  // another size.
  static SessionKey FromBytes(const uint8_t* bytes, std::size_t size);

  SessionKey(SessionKey&& other) noexcept;
  SessionKey& operator=(SessionKey&& other) noexcept;
  SessionKey(const SessionKey&) = delete;
  SessionKey& operator=(const SessionKey&) = delete;
  ~SessionKey();

  // kBytes bytes; valid while this object lives.
  const uint8_t* data() const { return bytes_; }

  // 16 hex digits identifying the key (keyed BLAKE2b, not reversible), so operators can
  // check that two machines hold the same key without showing it.
  std::string Id() const;

 private:
  SessionKey();  // allocates the guarded (writable) storage
  void Seal();   // read-only from now on

  uint8_t* bytes_ = nullptr;
};

}  // namespace snapthread::auth
