// The server's side of the roles (docs/security.md, "Roles: the key hierarchy"): the root
// key and, during a rotation, the previous one until its grace period ends; the revocation
// list; and the lookup of the key a device's or operator's message was made with.
//
// A message names its sender (role, name), its credential's expiry and the id of its key.
// Resolve re-derives the key from the claimed (name, expiry) under each root, and accepts
// it only when the id matches, the expiry is not reached, and neither the name nor the id
// is revoked; the caller then checks the message's MAC with the returned key. Nothing is
// registered when a credential is issued: the root key is all the server needs.
//
// Keys found are cached (each one once, at most kMaxCachedKeys), so a lookup after the
// first allocates nothing; expiry and revocation are checked at every lookup, so a
// reloaded revocation list acts on the running session. Not thread-safe: one thread owns
// the ring (the server's receive thread).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "auth/key_id.h"
#include "auth/revocation_list.h"
#include "auth/role.h"
#include "auth/session_key.h"
#include "auth/signature.h"

namespace snapthread::auth {

enum class KeyVerdict {
  kAccepted,
  kExpired,       // the claimed expiry has passed
  kRevoked,       // the name or the key id is on the revocation list
  kUnknownKey,    // no root gives this key id for the claimed (role, name, expiry)
  kGraceOver,     // made under the previous root after its grace period
  kInvalidClaim,  // not a named role, an invalid name, a negative expiry
};
std::string_view KeyVerdictToString(KeyVerdict verdict);

struct ResolvedKey {
  KeyVerdict verdict = KeyVerdict::kUnknownKey;
  // The key when accepted; valid until the next Resolve, Rotate or the ring's end.
  const SessionKey* key = nullptr;
  bool previous_root = false;  // accepted under the previous root (grace period)
};

class KeyRing {
 public:
  static constexpr std::size_t kMaxCachedKeys = 256;

  explicit KeyRing(SessionKey root);

  // A new root: the current one becomes the previous, accepted until
  // `grace_until_unix_s` (exclusive); an older previous one is dropped.
  void Rotate(SessionKey new_root, int64_t grace_until_unix_s);
  void SetRevocations(RevocationList list) { revoked_ = std::move(list); }

  ResolvedKey Resolve(Role role, std::string_view name, int64_t expires_unix_s, const KeyId& key_id,
                      int64_t now_unix_s);

  const SessionKey& root() const { return root_; }
  // The server signs with the current root's key; during the grace period also with the
  // previous one (nullptr otherwise), so receivers holding either public key verify it.
  const Signer& signer() const { return signer_; }
  const Signer* previous_signer(int64_t now_unix_s) const;

 private:
  struct Cached {
    Role role;
    std::string name;
    int64_t expires_unix_s;
    KeyId key_id;
    bool previous_root;
    SessionKey key;
  };
  const Cached* Find(Role role, std::string_view name, int64_t expires_unix_s, const KeyId& key_id) const;

  SessionKey root_;
  Signer signer_;
  std::optional<SessionKey> previous_;
  std::optional<Signer> previous_signer_;
  int64_t grace_until_unix_s_ = 0;
  RevocationList revoked_;
  std::vector<Cached> cache_;
};

}  // namespace snapthread::auth
