// The key hierarchy of the roles: every key a role holds is derived from the root key
// (today's 32-byte session key file, kept on the server host), so the server host needs
// no registry of issued credentials (docs/security.md, "Roles: the key hierarchy").
//
//   root ── crypto_kdf_derive_from_key(context "snapthrd")
//     ├─ id 1: server signing seed ── crypto_sign_seed_keypair ── Ed25519 (pk to everyone)
//     ├─ id 2: operator master ─┐
//     ├─ id 3: observer read key (AEAD of what the server publishes)
//     └─ id 4: device master ───┤
//                               └─ role key = BLAKE2b-256(key = master,
//                                     msg = role "\0" name "\0" le64(expiry_unix_s))
//   device key ── BLAKE2b-256(key = device key, msg = "snapthread-seal-v1")  AEAD key
//              └─ BLAKE2b-256(key = device key, msg = "snapthread-sign-v1")  Ed25519 seed
//
// A device's MAC key is bound to its name and expiry: a holder who edits either in its
// credential gets a key that no longer matches what the server re-derives from the
// claimed (name, expiry), so an expiry cannot be extended and one device's key never
// drives another grasp. The masters never leave the server host. An observer's
// credential holds only the server's public key and the read key, from which neither a
// master, a role key nor the signing seed can be computed (independent KDF outputs).
//
// Derivations throw std::invalid_argument for a name outside IsValidRoleName or a
// negative expiry; they allocate only the guarded storage of the result.
#pragma once

#include <cstdint>
#include <string_view>

#include "auth/key_id.h"
#include "auth/role.h"
#include "auth/session_key.h"
#include "auth/signature.h"

namespace snapthread::auth {

// The crypto_kdf context and subkey ids (part of the format: never renumber).
inline constexpr char kKdfContext[] = "snapthrd";
enum class KdfSubkey : uint64_t {
  kServerSignSeed = 1,
  kOperatorMaster = 2,
  kObserverReadKey = 3,
  kDeviceMaster = 4,
};

// The server's signer (what it publishes) and its public key.
Signer DeriveServerSigner(const SessionKey& root);
PublicKey DeriveServerPublicKey(const SessionKey& root);

// The observers' read key: the AEAD key of what the server publishes when payloads are
// sealed. Every credential carries it.
SessionKey DeriveReadKey(const SessionKey& root);

// A named role's MAC key (device or operator), bound to its name and expiry.
SessionKey DeriveDeviceKey(const SessionKey& root, std::string_view name, int64_t expires_unix_s);
SessionKey DeriveOperatorKey(const SessionKey& root, std::string_view name, int64_t expires_unix_s);
SessionKey DeriveRoleKey(const SessionKey& root, Role role, std::string_view name,
                         int64_t expires_unix_s);

// From a device's key: its AEAD key (its traffic with the server) and an Ed25519 signer,
// whose public key the server can re-derive and vouch for, for observers that show what a
// device publishes.
SessionKey DeriveDeviceSealKey(const SessionKey& device_key);
Signer DeriveDeviceSigner(const SessionKey& device_key);

// The label under which a role's symmetric key gets its id (SecretKeyId): "device",
// "operator", or "read" for the observer's read key; "root" for the server.
std::string_view KeyIdLabel(Role role);

namespace detail {
// DeriveRoleKey into caller memory (SessionKey::kBytes), for the key ring's lookups: no
// allocation, no exception; false for an invalid role, name or expiry.
[[nodiscard]] bool DeriveRoleKeyInto(const SessionKey& root, Role role, std::string_view name,
                                     int64_t expires_unix_s, uint8_t* out) noexcept;
}  // namespace detail

}  // namespace snapthread::auth
