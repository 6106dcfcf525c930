// What `--key` gave a program (docs/security.md, "Roles on the wire"): the root key (the
// server host, which may act in any role) or one role's credential, with the taggers and
// keys that role uses. Every program loads its KeySet once at start-up with the role it
// plays; a credential of another role is refused there, naming the role needed.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "auth/credential.h"
#include "auth/device_certificate.h"
#include "auth/key_file.h"
#include "auth/key_id.h"
#include "auth/message_mac.h"
#include "auth/role.h"
#include "auth/session_key.h"
#include "auth/signature.h"

namespace snapthread::auth {

class KeySet {
 public:
  // The server host: the root key. It tags as the server (taggers below) and can issue
  // itself any role (ForRole).
  static KeySet FromRoot(SessionKey root);
  // A role's credential (device, observer, operator).
  static KeySet FromCredential(Credential credential);
  // A credential issued from `root` for `role` (tests and server-host tools): the KeySet
  // holds the root too, so that it can also check everything.
  static KeySet ForRole(const SessionKey& root, Role role, std::string_view name = {},
                        int64_t expires_unix_s = kNeverExpires);

  KeySet(KeySet&&) noexcept;
  KeySet& operator=(KeySet&&) noexcept;
  ~KeySet();

  // kServer for the root key, else the credential's role.
  Role role() const { return role_; }
  const SessionKey* root() const { return root_ ? &*root_ : nullptr; }
  const Credential* credential() const { return credential_ ? &*credential_ : nullptr; }
  // The credential's name (device, operator); "" for the server and observers.
  const std::string& name() const { return tagger_.name; }
  int64_t expires_unix_s() const { return credential_ ? credential_->expires_unix_s : kNeverExpires; }

  // Verifies what the server signs.
  const PublicKey& server_public_key() const { return server_public_key_; }
  // Opens what is sealed (every role holds it).
  const SessionKey& read_key() const { return *read_key_; }
  // A device's or operator's MAC key (the one its messages and the server's force models
  // for it carry); nullptr for the server and observers.
  const SessionKey* mac_key() const { return credential_ && credential_->secret ? &*credential_->secret : nullptr; }

  // How this program tags what it publishes: the server signs (no MAC); a device or an
  // operator MACs with its key; an observer tags nothing (no signer, no MAC).
  const Tagger& tagger() const { return tagger_; }
  // A device's status: its MAC and its own signature (nullptr for other roles).
  const Tagger* device_status_tagger() const { return device_signer_ ? &status_tagger_ : nullptr; }
  // How the server tags force models addressed to this device: a MAC under the device's
  // key, claiming the server's role and naming the device (devices only: no MAC otherwise;
  // tests and tools that stand in for the server).
  Tagger ForceModelTagger() const;
  // The device's public key and the server's certificate of it (devices only).
  const PublicKey* device_public_key() const { return device_signer_ ? &device_signer_->public_key() : nullptr; }
  const DeviceCertificateBytes* device_certificate() const { return certificate_ ? &*certificate_ : nullptr; }

 private:
  KeySet() = default;
  void BuildTaggers();

  Role role_ = Role::kObserver;
  std::optional<SessionKey> root_;
  std::optional<Credential> credential_;
  std::optional<Signer> server_signer_;  // root holders
  std::optional<Signer> device_signer_;  // devices
  std::optional<DeviceCertificateBytes> certificate_;
  PublicKey server_public_key_{};
  std::optional<SessionKey> read_key_;
  Tagger tagger_;
  Tagger status_tagger_;
};

// Loads --key at `path` for a program playing `needed`: a 32-byte root key file (accepted
// for every role: the server host may run anything) or a credential file (auth/credential.h),
// told apart by the credential's first line. A credential must be of role `needed` and
// unexpired; otherwise throws CredentialError naming `program`, the role it needs, what
// the file is, and the fix. A key file error is a KeyFileError as today.
KeySet LoadKeySet(const std::string& path, Role needed, std::string_view program);
// The same for a resolved --key (auth/key_file.h), whose origin the messages name.
KeySet LoadKeySet(const KeyLocation& where, Role needed, std::string_view program);

// Whether the file at `path` starts like a credential (its first line); false when it
// cannot be read (the loader then says why).
bool LooksLikeCredential(const std::string& path);

}  // namespace snapthread::auth
