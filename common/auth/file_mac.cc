#include "auth/file_mac.h"

#include <sodium.h>

namespace snapthread::auth {

static_assert(kFileChecksumBytes >= crypto_generichash_BYTES_MIN &&
              kFileChecksumBytes <= crypto_generichash_BYTES_MAX);
static_assert(kFileMacBytes == crypto_auth_hmacsha512256_BYTES);
static_assert(crypto_auth_BYTES == crypto_auth_hmacsha512256_BYTES);  // crypto_auth is this

namespace {

constexpr std::string_view kDomainPrefix = "snapthread-file-v1";

}  // namespace

void FileChecksum(const void* data, std::size_t size, uint8_t out[kFileChecksumBytes]) {
  InitSodium();
  crypto_generichash(out, kFileChecksumBytes, static_cast<const unsigned char*>(data), size,
                     nullptr, 0);
}

void FileMac(std::string_view domain, const void* data, std::size_t size, const SessionKey& key,
             uint8_t tag[kFileMacBytes]) {
  InitSodium();
  crypto_auth_hmacsha512256_state state;
  crypto_auth_hmacsha512256_init(&state, key.data(), SessionKey::kBytes);
  crypto_auth_hmacsha512256_update(&state,
                                   reinterpret_cast<const unsigned char*>(kDomainPrefix.data()),
                                   kDomainPrefix.size());
  const auto length = static_cast<uint32_t>(domain.size());
  const unsigned char length_be[4] = {static_cast<unsigned char>(length >> 24),
                                      static_cast<unsigned char>(length >> 16),
                                      static_cast<unsigned char>(length >> 8),
                                      static_cast<unsigned char>(length)};
  crypto_auth_hmacsha512256_update(&state, length_be, sizeof(length_be));
  crypto_auth_hmacsha512256_update(&state, reinterpret_cast<const unsigned char*>(domain.data()),
                                   domain.size());
  crypto_auth_hmacsha512256_update(&state, static_cast<const unsigned char*>(data), size);
  crypto_auth_hmacsha512256_final(&state, tag);
  sodium_memzero(&state, sizeof(state));
}

bool VerifyFileMac(std::string_view domain, const void* data, std::size_t size,
                   const SessionKey& key, const uint8_t tag[kFileMacBytes]) {
  uint8_t expected[kFileMacBytes];
  FileMac(domain, data, size, key, expected);
  const bool ok = sodium_memcmp(expected, tag, kFileMacBytes) == 0;
  sodium_memzero(expected, sizeof(expected));
  return ok;
}

}  // namespace snapthread::auth
