#include "auth/signature.h"

#include <sodium.h>

#include <new>
#include <utility>

namespace snapthread::auth {

static_assert(kSignatureBytes == crypto_sign_BYTES);
static_assert(kSignSeedBytes == crypto_sign_SEEDBYTES);
static_assert(kPublicKeyBytes == crypto_sign_PUBLICKEYBYTES);

Signer Signer::FromSeed(const uint8_t seed[kSignSeedBytes]) {
  InitSodium();
  Signer signer;
  signer.secret_ = static_cast<uint8_t*>(sodium_malloc(crypto_sign_SECRETKEYBYTES));
  if (signer.secret_ == nullptr) throw std::bad_alloc();
  crypto_sign_seed_keypair(signer.public_key_.data(), signer.secret_, seed);
  sodium_mprotect_readonly(signer.secret_);
  return signer;
}

Signer::Signer(Signer&& other) noexcept
    : secret_(std::exchange(other.secret_, nullptr)), public_key_(other.public_key_) {}

Signer& Signer::operator=(Signer&& other) noexcept {
  if (this != &other) {
    if (secret_ != nullptr) sodium_free(secret_);
    secret_ = std::exchange(other.secret_, nullptr);
    public_key_ = other.public_key_;
  }
  return *this;
}

// sodium_free wipes the secret key before unmapping it.
Signer::~Signer() {
  if (secret_ != nullptr) sodium_free(secret_);
}

void Signer::Sign(const void* data, std::size_t size, uint8_t signature[kSignatureBytes]) const noexcept {
  crypto_sign_detached(signature, nullptr, static_cast<const uint8_t*>(data), size, secret_);
}

bool SignatureVerifier::Verify(const void* data, std::size_t size,
                               const uint8_t signature[kSignatureBytes]) const noexcept {
  return crypto_sign_verify_detached(signature, static_cast<const uint8_t*>(data), size,
                                     public_key_.data()) == 0;
}

}  // namespace snapthread::auth
