// A role's credential: what a device, an observer or an operator holds instead of the
// root key (docs/security.md, "Roles: the key hierarchy"; the derivations are in
// auth/role_keys.h), and its text form.
//
//   snapthread-credential 1
//   role device                      device | operator | observer
//   name left                        devices and operators only: [A-Za-z0-9_-]{1,32}
//   expires 1798761600               Unix seconds, or "never"
//   root_id 0123456789abcdef         the root key it was issued from (rotation)
//   key_id 89abcdef01234567          the id of `secret` (observer: of `read_key`)
//   server_public_key <64 hex>       verifies what the server signs
//   read_key <64 hex>                opens what the server seals
//   secret <64 hex>                  devices and operators only: the MAC key
//   certificate <128 hex>            devices only: the server's DeviceCertificate of the
//                                    device's signing key (auth/device_certificate.h)
//
// One "word value" a line, single spaces, "\n" endings, each line once, in any order after
// the first. Parsing is strict: an unknown, repeated or missing line, a line of another
// role, bad hex, a wrong length, an invalid name or expiry, a key id that does not match
// the key, or a device certificate that server_public_key does not verify is refused with a CredentialError naming the file, the line and the fix.
// The server takes no credential: it holds the root key file itself.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "auth/device_certificate.h"
#include "auth/key_id.h"
#include "auth/role.h"
#include "auth/session_key.h"

namespace snapthread::auth {

inline constexpr int kCredentialFormatVersion = 1;

// A credential that cannot be used; what() names the file (or the caller) and the fix.
class CredentialError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Credential {
  Role role = Role::kObserver;
  std::string name;                       // devices and operators; empty for an observer
  int64_t expires_unix_s = kNeverExpires;
  KeyId root_id{};
  KeyId key_id{};
  PublicKey server_public_key{};
  std::optional<SessionKey> read_key;     // every credential
  std::optional<SessionKey> secret;       // devices and operators: the MAC key
  // Devices: DeviceCertificate(server signer, name, expiry, DeriveDeviceSigner(*secret)
  // .public_key()), which the device publishes with its statuses for observers.
  std::optional<DeviceCertificateBytes> certificate;

  bool ExpiredAt(int64_t now_unix_s) const { return IsExpired(expires_unix_s, now_unix_s); }
};

// A credential for `role` from the root key (a device's with its certificate). Devices
// and operators need a valid name, observers none; `expires_unix_s` is kNeverExpires or a positive time. Throws
// CredentialError (a server credential, a bad name, a negative expiry).
Credential IssueCredential(const SessionKey& root, Role role, std::string_view name,
                           int64_t expires_unix_s);

// The text form above (holds secrets: the caller wipes it, sodium_memzero).
std::string FormatCredential(const Credential& credential);
// Parses the text form; `source` names it in the messages (a file path). Throws
// CredentialError.
Credential ParseCredential(std::string_view text, const std::string& source);

// Throws CredentialError unless `credential` is of role `needed`: e.g. "snapthread-device
// needs a device credential; /x/left.cred is an observer credential. Fix: ...". `user`
// names the program that needs it, `source` the file.
void RequireRole(const Credential& credential, Role needed, std::string_view user,
                 const std::string& source);

}  // namespace snapthread::auth
