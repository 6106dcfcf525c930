#include "auth/session_key.h"

#include <sodium.h>

#include <new>
#include <stdexcept>
#include <string>
#include <utility>

namespace snapthread::auth {

static_assert(SessionKey::kBytes == crypto_auth_KEYBYTES);

void InitSodium() {
  // sodium_init() returns 0 the first time, 1 when already done, -1 on failure.
  if (sodium_init() < 0) {
    throw std::runtime_error("libsodium failed to initialise (no usable random source?)");
  }
}

SessionKey::SessionKey() {
  InitSodium();
  bytes_ = static_cast<uint8_t*>(sodium_malloc(kBytes));
  if (bytes_ == nullptr) throw std::bad_alloc();
}

SessionKey SessionKey::Generate() {
  SessionKey key;
  randombytes_buf(key.bytes_, kBytes);
  key.Seal();
  return key;
}

SessionKey SessionKey::FromBytes(const uint8_t* bytes, std::size_t size) {
  if (size != kBytes) {
    throw std::invalid_argument("a session key is " + std::to_string(kBytes) + " bytes, not " +
                                std::to_string(size));
  }
  SessionKey key;
  for (std::size_t i = 0; i < kBytes; ++i) key.bytes_[i] = bytes[i];
  key.Seal();
  return key;
}

std::string SessionKey::Id() const {
  static constexpr char kContext[] = "snapthread key id";
  // BLAKE2b keyed with the session key (a PRF of it): shows nothing about the key.
  uint8_t hash[crypto_generichash_BYTES_MIN];
  crypto_generichash(hash, sizeof hash, reinterpret_cast<const uint8_t*>(kContext),
                     sizeof kContext - 1, bytes_, kBytes);
  std::string id(16, '0');
  sodium_bin2hex(id.data(), id.size() + 1, hash, id.size() / 2);
  return id;
}

void SessionKey::Seal() { sodium_mprotect_readonly(bytes_); }

SessionKey::SessionKey(SessionKey&& other) noexcept : bytes_(std::exchange(other.bytes_, nullptr)) {}

SessionKey& SessionKey::operator=(SessionKey&& other) noexcept {
  if (this != &other) {
    if (bytes_ != nullptr) sodium_free(bytes_);
    bytes_ = std::exchange(other.bytes_, nullptr);
  }
  return *this;
}

// sodium_free zeroes the bytes (sodium_memzero) before unmapping them.
SessionKey::~SessionKey() {
  if (bytes_ != nullptr) sodium_free(bytes_);
}

}  // namespace snapthread::auth
