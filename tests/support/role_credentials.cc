#include "role_credentials.h"

#include "auth/credential.h"
#include "auth/credential_file.h"
#include "auth/key_file.h"

namespace snapthread::test_support {

RoleCredentials::RoleCredentials(const std::string& name)
    : dir_(name), root_path_(dir_.path() + "/root.key") {
  auth::WriteNewKey(auth::KeyLocation{root_path_, "test"}, /*overwrite=*/false);
}

auth::SessionKey RoleCredentials::Root() const { return auth::LoadKey(auth::KeyLocation{root_path_, "test"}); }

std::string RoleCredentials::Issue(auth::Role role, const std::string& name, const std::string& file,
                                   bool overwrite, int64_t expires_unix_s) const {
  std::string base = file;
  if (base.empty()) {
    base = std::string(auth::RoleToString(role)) + (name.empty() ? "" : "-" + name) + ".cred";
  }
  const std::string path = dir() + "/" + base;
  const auth::Credential credential = auth::IssueCredential(Root(), role, name, expires_unix_s);
  auth::WriteCredentialFile(path, credential, overwrite);
  return path;
}

auth::KeySet RoleCredentials::Load(const std::string& path, auth::Role role) {
  return auth::LoadKeySet(path, role, "role test");
}

}  // namespace snapthread::test_support
