#include "auth/aead.h"

#include <sodium.h>

namespace snapthread::auth {

static_assert(kAeadNonceBytes == crypto_aead_xchacha20poly1305_ietf_NPUBBYTES);
static_assert(kAeadTagBytes == crypto_aead_xchacha20poly1305_ietf_ABYTES);
static_assert(SessionKey::kBytes == crypto_aead_xchacha20poly1305_ietf_KEYBYTES);

bool Seal(const SessionKey& key, ByteView plain, ByteView associated, uint8_t* out,
          std::size_t out_capacity, std::size_t* out_size) noexcept {
  *out_size = 0;
  if (out == nullptr || plain.size > out_capacity ||
      out_capacity - plain.size < kAeadOverheadBytes) {
    return false;
  }
  randombytes_buf(out, kAeadNonceBytes);
  unsigned long long sealed = 0;
  crypto_aead_xchacha20poly1305_ietf_encrypt(out + kAeadNonceBytes, &sealed, plain.data, plain.size,
                                             associated.data, associated.size, nullptr, out,
                                             key.data());
  *out_size = kAeadNonceBytes + static_cast<std::size_t>(sealed);
  return true;
}

bool Open(const SessionKey& key, ByteView sealed, ByteView associated, uint8_t* plain_out,
          std::size_t plain_capacity, std::size_t* plain_size) noexcept {
  *plain_size = 0;
  if (sealed.data == nullptr || sealed.size < kAeadOverheadBytes || plain_out == nullptr ||
      plain_capacity < sealed.size - kAeadOverheadBytes) {
    return false;
  }
  unsigned long long opened = 0;
  const int rc = crypto_aead_xchacha20poly1305_ietf_decrypt(
      plain_out, &opened, nullptr, sealed.data + kAeadNonceBytes, sealed.size - kAeadNonceBytes,
      associated.data, associated.size, sealed.data, key.data());
  if (rc != 0) {
    sodium_memzero(plain_out, sealed.size - kAeadOverheadBytes);
    return false;
  }
  *plain_size = static_cast<std::size_t>(opened);
  return true;
}

}  // namespace snapthread::auth
