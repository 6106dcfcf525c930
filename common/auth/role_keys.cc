#include "auth/role_keys.h"

#include <sodium.h>

#include <stdexcept>
#include <string>

namespace snapthread::auth {

static_assert(sizeof kKdfContext - 1 == crypto_kdf_CONTEXTBYTES);
static_assert(SessionKey::kBytes == crypto_kdf_KEYBYTES);

namespace {

// A 32-byte subkey of the root into `out`.
void DeriveSubkey(const SessionKey& root, KdfSubkey id, uint8_t out[SessionKey::kBytes]) noexcept {
  crypto_kdf_derive_from_key(out, SessionKey::kBytes, static_cast<uint64_t>(id), kKdfContext,
                             root.data());
}

// BLAKE2b-256 keyed with `key` over `label`: a one-way subkey of a role key.
SessionKey KeyedSubkey(const SessionKey& key, std::string_view label) {
  uint8_t bytes[SessionKey::kBytes];
  crypto_generichash(bytes, sizeof bytes, reinterpret_cast<const uint8_t*>(label.data()),
                     label.size(), key.data(), SessionKey::kBytes);
  SessionKey sub = SessionKey::FromBytes(bytes, sizeof bytes);
  sodium_memzero(bytes, sizeof bytes);
  return sub;
}

}  // namespace

std::string_view KeyIdLabel(Role role) {
  switch (role) {
    case Role::kServer: return "root";
    case Role::kDevice: return "device";
    case Role::kObserver: return "read";
    case Role::kOperator: return "operator";
  }
  return "unknown";
}

Signer DeriveServerSigner(const SessionKey& root) {
  uint8_t seed[SessionKey::kBytes];
  DeriveSubkey(root, KdfSubkey::kServerSignSeed, seed);
  Signer signer = Signer::FromSeed(seed);
  sodium_memzero(seed, sizeof seed);
  return signer;
}

PublicKey DeriveServerPublicKey(const SessionKey& root) { return DeriveServerSigner(root).public_key(); }

SessionKey DeriveReadKey(const SessionKey& root) {
  uint8_t bytes[SessionKey::kBytes];
  DeriveSubkey(root, KdfSubkey::kObserverReadKey, bytes);
  SessionKey key = SessionKey::FromBytes(bytes, sizeof bytes);
  sodium_memzero(bytes, sizeof bytes);
  return key;
}

namespace detail {

bool DeriveRoleKeyInto(const SessionKey& root, Role role, std::string_view name,
                       int64_t expires_unix_s, uint8_t* out) noexcept {
  if (!RoleIsNamed(role) || !IsValidRoleName(name) || expires_unix_s < 0) return false;
  uint8_t master[SessionKey::kBytes];
  DeriveSubkey(root, role == Role::kDevice ? KdfSubkey::kDeviceMaster : KdfSubkey::kOperatorMaster,
               master);
  // role "\0" name "\0" le64(expiry): the NULs keep (role, name) pairs apart, the name's
  // grammar has no NUL, and the expiry has a fixed width.
  const std::string_view role_word = RoleToString(role);
  uint8_t expiry[8];
  for (int i = 0; i < 8; ++i) expiry[i] = static_cast<uint8_t>(static_cast<uint64_t>(expires_unix_s) >> (8 * i));
  const uint8_t nul = 0;
  crypto_generichash_state state;
  crypto_generichash_init(&state, master, sizeof master, SessionKey::kBytes);
  crypto_generichash_update(&state, reinterpret_cast<const uint8_t*>(role_word.data()), role_word.size());
  crypto_generichash_update(&state, &nul, 1);
  crypto_generichash_update(&state, reinterpret_cast<const uint8_t*>(name.data()), name.size());
  crypto_generichash_update(&state, &nul, 1);
  crypto_generichash_update(&state, expiry, sizeof expiry);
  crypto_generichash_final(&state, out, SessionKey::kBytes);
  sodium_memzero(&state, sizeof state);
  sodium_memzero(master, sizeof master);
  return true;
}

}  // namespace detail

SessionKey DeriveRoleKey(const SessionKey& root, Role role, std::string_view name,
                         int64_t expires_unix_s) {
  if (!RoleIsNamed(role)) {
    throw std::invalid_argument("a " + std::string(RoleToString(role)) +
                                " has no named key (only devices and operators do)");
  }
  if (!IsValidRoleName(name)) {
    throw std::invalid_argument("'" + std::string(name) + "' is not a valid " +
                                std::string(RoleToString(role)) + " name (1 to 32 of A-Z a-z 0-9 _ -)");
  }
  if (expires_unix_s < 0) throw std::invalid_argument("a negative expiry");
  uint8_t bytes[SessionKey::kBytes];
  const bool ok = detail::DeriveRoleKeyInto(root, role, name, expires_unix_s, bytes);
  (void)ok;  // checked above
  SessionKey key = SessionKey::FromBytes(bytes, sizeof bytes);
  sodium_memzero(bytes, sizeof bytes);
  return key;
}

SessionKey DeriveDeviceKey(const SessionKey& root, std::string_view name, int64_t expires_unix_s) {
  return DeriveRoleKey(root, Role::kDevice, name, expires_unix_s);
}

SessionKey DeriveOperatorKey(const SessionKey& root, std::string_view name, int64_t expires_unix_s) {
  return DeriveRoleKey(root, Role::kOperator, name, expires_unix_s);
}

SessionKey DeriveDeviceSealKey(const SessionKey& device_key) {
  return KeyedSubkey(device_key, "snapthread-seal-v1");
}

Signer DeriveDeviceSigner(const SessionKey& device_key) {
  const SessionKey seed = KeyedSubkey(device_key, "snapthread-sign-v1");
  return Signer::FromSeed(seed.data());
}

}  // namespace snapthread::auth
