// The credentials the server no longer accepts (docs/security.md, "Roles: the key
// hierarchy"): a text file on the server host, read at start and on reload, so one
// device or operator can be shut out without re-keying the session.
//
//   # comments and blank lines are allowed
//   device left                 every credential of device "left", whatever its expiry
//   operator alice              every credential of operator "alice"
//   key_id 0123456789abcdef     one credential (its key id, as in the credential file)
//
// The file follows the rules of a private file (auth/private_file.h: whoever could write
// it could lift a revocation). Parsing is strict: an unknown word, a bad name or key id,
// extra words or a CRLF line is a RevocationListError naming the file, the line and the
// fix. A repeated entry is accepted (revoking twice is harmless).
#pragma once

#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "auth/key_id.h"
#include "auth/role.h"

namespace snapthread::auth {

class RevocationListError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr std::size_t kMaxRevocationListBytes = 1u << 20;

class RevocationList {
 public:
  RevocationList() = default;  // revokes nothing

  static RevocationList Parse(std::string_view text, const std::string& source);
  // Reads `path` under the private file rules (at most kMaxRevocationListBytes).
  static RevocationList Load(const std::string& path);
  // Appends `lines` (whole lines of the format above, each ending in "\n") to the list at
  // `path`, creating it (mode 0600, parents 0700) when missing, and returns the new list.
  // The file is replaced atomically, so a server reloading meanwhile reads the old or the
  // new list whole. Refuses (RevocationListError, nothing written) an existing list that
  // does not load and lines that do not parse.
  static RevocationList Append(const std::string& path, std::string_view lines);

  // Whether a credential of `role` named `name` with key id `key_id` is revoked: by its
  // name (devices and operators) or by its key id. Allocates nothing.
  bool IsRevoked(Role role, std::string_view name, const KeyId& key_id) const noexcept;

  std::size_t size() const { return names_.size() + key_ids_.size(); }
  // The revoked (role, name) pairs and key ids, in order (for listing them).
  const std::set<std::pair<Role, std::string>, std::less<>>& names() const { return names_; }
  const std::set<KeyId>& key_ids() const { return key_ids_; }

 private:
  std::set<std::pair<Role, std::string>, std::less<>> names_;
  std::set<KeyId> key_ids_;
};

}  // namespace snapthread::auth
