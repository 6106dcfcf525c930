#include "auth/key_id.h"

#include <sodium.h>

#include <string>

namespace snapthread::auth {
namespace {

constexpr std::string_view kIdDomain = "snapthread-key-id-v1 ";

}  // namespace

KeyId SecretKeyId(std::string_view label, const uint8_t* key_bytes) {
  // The label, prefixed by the domain, hashed under the key (BLAKE2b's keyed mode is a PRF).
  crypto_generichash_state state;
  crypto_generichash_init(&state, key_bytes, SessionKey::kBytes, crypto_generichash_BYTES_MIN);
  crypto_generichash_update(&state, reinterpret_cast<const uint8_t*>(kIdDomain.data()), kIdDomain.size());
  crypto_generichash_update(&state, reinterpret_cast<const uint8_t*>(label.data()), label.size());
  uint8_t hash[crypto_generichash_BYTES_MIN];
  crypto_generichash_final(&state, hash, sizeof hash);
  KeyId id{};
  for (std::size_t i = 0; i < kKeyIdBytes; ++i) id[i] = hash[i];
  sodium_memzero(&state, sizeof state);
  return id;
}

KeyId SecretKeyId(std::string_view label, const SessionKey& key) {
  return SecretKeyId(label, key.data());
}

KeyId PublicKeyId(const PublicKey& key) {
  constexpr std::string_view kLabel = "snapthread-key-id-v1 ed25519";
  crypto_generichash_state state;
  crypto_generichash_init(&state, nullptr, 0, crypto_generichash_BYTES_MIN);
  crypto_generichash_update(&state, reinterpret_cast<const uint8_t*>(kLabel.data()), kLabel.size());
  crypto_generichash_update(&state, key.data(), key.size());
  uint8_t hash[crypto_generichash_BYTES_MIN];
  crypto_generichash_final(&state, hash, sizeof hash);
  KeyId id{};
  for (std::size_t i = 0; i < kKeyIdBytes; ++i) id[i] = hash[i];
  return id;
}

KeyId RootKeyId(const SessionKey& root) {
  KeyId id{};
  const bool ok = FromHex(root.Id(), id.data(), id.size());
  (void)ok;  // Id() is always 16 hex digits
  return id;
}

std::string ToHex(const uint8_t* bytes, std::size_t size) {
  std::string hex(2 * size + 1, '\0');
  sodium_bin2hex(hex.data(), hex.size(), bytes, size);
  hex.pop_back();
  return hex;
}

std::string KeyIdToHex(const KeyId& id) { return ToHex(id.data(), id.size()); }

bool FromHex(std::string_view hex, uint8_t* out, std::size_t size) {
  if (hex.size() != 2 * size) return false;
  std::size_t written = 0;
  const char* end = nullptr;
  // No ignored characters: anything but hex digits stops the parse before the end.
  if (sodium_hex2bin(out, size, hex.data(), hex.size(), nullptr, &written, &end) != 0) return false;
  return written == size && end == hex.data() + hex.size();
}

std::optional<KeyId> KeyIdFromHex(std::string_view hex) {
  KeyId id{};
  if (!FromHex(hex, id.data(), id.size())) return std::nullopt;
  return id;
}

}  // namespace snapthread::auth
