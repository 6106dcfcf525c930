#include "auth/key_ring.h"

#include <sodium.h>

#include "auth/role_keys.h"

namespace snapthread::auth {

std::string_view KeyVerdictToString(KeyVerdict verdict) {
  switch (verdict) {
    case KeyVerdict::kAccepted: return "accepted";
    case KeyVerdict::kExpired: return "credential expired";
    case KeyVerdict::kRevoked: return "credential revoked";
    case KeyVerdict::kUnknownKey: return "unknown key";
    case KeyVerdict::kGraceOver: return "previous root key past its grace period";
    case KeyVerdict::kInvalidClaim: return "invalid role, name or expiry";
  }
  return "unknown";
}

KeyRing::KeyRing(SessionKey root) : root_(std::move(root)), signer_(DeriveServerSigner(root_)) {
  cache_.reserve(kMaxCachedKeys);
}

void KeyRing::Rotate(SessionKey new_root, int64_t grace_until_unix_s) {
  previous_signer_.emplace(std::move(signer_));
  previous_.emplace(std::move(root_));
  root_ = std::move(new_root);
  signer_ = DeriveServerSigner(root_);
  grace_until_unix_s_ = grace_until_unix_s;
  cache_.clear();
}

const Signer* KeyRing::previous_signer(int64_t now_unix_s) const {
  if (!previous_signer_ || now_unix_s >= grace_until_unix_s_) return nullptr;
  return &*previous_signer_;
}

const KeyRing::Cached* KeyRing::Find(Role role, std::string_view name, int64_t expires_unix_s,
                                     const KeyId& key_id) const {
  for (const Cached& c : cache_) {
    if (c.role == role && c.expires_unix_s == expires_unix_s && c.key_id == key_id && c.name == name) {
      return &c;
    }
  }
  return nullptr;
}

ResolvedKey KeyRing::Resolve(Role role, std::string_view name, int64_t expires_unix_s,
                             const KeyId& key_id, int64_t now_unix_s) {
  // Cheapest refusals first: the claim itself, its expiry, the revocation list.
  if (!RoleIsNamed(role) || !IsValidRoleName(name) || expires_unix_s < 0) {
    return {KeyVerdict::kInvalidClaim, nullptr, false};
  }
  if (IsExpired(expires_unix_s, now_unix_s)) return {KeyVerdict::kExpired, nullptr, false};
  if (revoked_.IsRevoked(role, name, key_id)) return {KeyVerdict::kRevoked, nullptr, false};
  if (const Cached* c = Find(role, name, expires_unix_s, key_id); c != nullptr) {
    if (c->previous_root && now_unix_s >= grace_until_unix_s_) return {KeyVerdict::kGraceOver, nullptr, true};
    return {KeyVerdict::kAccepted, &c->key, c->previous_root};
  }
  // Re-derive under each root in a stack buffer; only a key whose id matches is kept.
  const std::string_view label = KeyIdLabel(role);
  uint8_t bytes[SessionKey::kBytes];
  bool found = false, previous = false;
  const SessionKey* roots[2] = {&root_, previous_ ? &*previous_ : nullptr};
  for (int r = 0; r < 2 && !found; ++r) {
    if (roots[r] == nullptr || !detail::DeriveRoleKeyInto(*roots[r], role, name, expires_unix_s, bytes)) continue;
    if (sodium_memcmp(SecretKeyId(label, bytes).data(), key_id.data(), kKeyIdBytes) == 0) {
      found = true;
      previous = r == 1;
    }
  }
  if (!found) {
    sodium_memzero(bytes, sizeof bytes);
    return {KeyVerdict::kUnknownKey, nullptr, false};
  }
  if (previous && now_unix_s >= grace_until_unix_s_) {
    sodium_memzero(bytes, sizeof bytes);
    return {KeyVerdict::kGraceOver, nullptr, true};
  }
  if (cache_.size() >= kMaxCachedKeys) cache_.clear();
  cache_.push_back({role, std::string(name), expires_unix_s, key_id, previous,
                    SessionKey::FromBytes(bytes, sizeof bytes)});
  sodium_memzero(bytes, sizeof bytes);
  return {KeyVerdict::kAccepted, &cache_.back().key, previous};
}

}  // namespace snapthread::auth
