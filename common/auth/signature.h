// Ed25519 signatures (libsodium crypto_sign_detached): what lets an observer verify what
// the server publishes while holding nothing that signs. The server's signer is derived
// from the root key (auth/role_keys.h); observers, devices and operators hold only its
// public key.
//
// Sign and Verify take the caller's bytes and a caller's 64-byte buffer: they allocate
// nothing and never throw. The caller signs a domain-separated encoding (a label, the
// channel, the message), as auth/message_mac.h does for MACs.
#pragma once

#include <cstddef>
#include <cstdint>

#include "auth/key_id.h"

namespace snapthread::auth {

inline constexpr std::size_t kSignatureBytes = 64;  // crypto_sign_BYTES
inline constexpr std::size_t kSignSeedBytes = 32;   // crypto_sign_SEEDBYTES

class Signer {
 public:
  // The key pair of a 32-byte seed (crypto_sign_seed_keypair): the same seed, the same pair.
  static Signer FromSeed(const uint8_t seed[kSignSeedBytes]);

  Signer(Signer&& other) noexcept;
  Signer& operator=(Signer&& other) noexcept;
  Signer(const Signer&) = delete;
  Signer& operator=(const Signer&) = delete;
  ~Signer();

  void Sign(const void* data, std::size_t size, uint8_t signature[kSignatureBytes]) const noexcept;
  const PublicKey& public_key() const { return public_key_; }
  KeyId key_id() const { return PublicKeyId(public_key_); }

 private:
  Signer() = default;
  uint8_t* secret_ = nullptr;  // crypto_sign_SECRETKEYBYTES in sodium_malloc, read-only
  PublicKey public_key_{};
};

class SignatureVerifier {
 public:
  explicit SignatureVerifier(const PublicKey& key) : public_key_(key) {}
  // Whether `signature` is this key's signature of the bytes (crypto_sign_verify_detached).
  [[nodiscard]] bool Verify(const void* data, std::size_t size,
                            const uint8_t signature[kSignatureBytes]) const noexcept;
  const PublicKey& public_key() const { return public_key_; }
  KeyId key_id() const { return PublicKeyId(public_key_); }

 private:
  PublicKey public_key_;
};

}  // namespace snapthread::auth
