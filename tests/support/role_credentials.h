// A session's keys for the role tests (docs/security.md, "Roles"): a root key in a private
// temporary directory (mode 0700, as the key loaders require), and credentials issued from
// it (auth::IssueCredential, written with auth::WriteCredentialFile), so that each program
// of a test can be started on the key of the role it plays: the server on the root, a
// device on "hand", a viewer on an observer credential, snapthread-ctl on an operator's.
#pragma once

#include <string>

#include "auth/key_set.h"
#include "auth/role.h"
#include "auth/session_key.h"
#include "temp_dir.h"

namespace snapthread::test_support {

class RoleCredentials {
 public:
  // A fresh root key at dir()/root.key.
  explicit RoleCredentials(const std::string& name = "roles");
  RoleCredentials(const RoleCredentials&) = delete;
  RoleCredentials& operator=(const RoleCredentials&) = delete;

  const std::string& dir() const { return dir_.path(); }
  // The root key file (the server's --key; snapthread-keygen --rotate replaces it).
  const std::string& root_path() const { return root_path_; }
  // The root key as the file holds it now (after a rotation: the new one).
  auth::SessionKey Root() const;

  // Issues a credential of `role` (devices and operators: `name`) from the root key as the
  // file holds it now, into dir()/<file> (default "<role>[-<name>].cred"); returns its path.
  // `overwrite` replaces an existing file (a rotated device's new credential).
  std::string Issue(auth::Role role, const std::string& name = "", const std::string& file = "",
                    bool overwrite = false, int64_t expires_unix_s = auth::kNeverExpires) const;

  // What a program given the file at `path` for `role` holds (auth::LoadKeySet).
  static auth::KeySet Load(const std::string& path, auth::Role role);

 private:
  ScopedTempDir dir_;
  std::string root_path_;
};

}  // namespace snapthread::test_support
