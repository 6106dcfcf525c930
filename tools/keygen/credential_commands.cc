#include "credential_commands.h"

#include <cstdio>
#include <filesystem>
#include <string>

#include "auth/credential.h"
#include "auth/credential_file.h"
#include "auth/key_file.h"
#include "auth/revocation_list.h"

namespace snapthread::keygen {
namespace {

using auth::Role;

// The program a credential of `role` is for.
const char* ProgramOf(Role role) {
  switch (role) {
    case Role::kDevice: return "snapthread-device";
    case Role::kOperator: return "snapthread-ctl";
    case Role::kObserver: return "snapthread-viewer, snapthread-web";
    case Role::kServer: break;
  }
  return "snapthread-server";
}

// A note when the revocation list beside the root key already shuts this credential out
// (a revoked name stays revoked for every expiry).
void WarnIfRevoked(const std::string& root_path, const auth::Credential& c) {
  const std::string path = RevokedPath(root_path);
  if (!std::filesystem::exists(std::filesystem::symlink_status(path))) return;
  try {
    if (auth::RevocationList::Load(path).IsRevoked(c.role, c.name, c.key_id)) {
      std::fprintf(stderr,
                   "snapthread-keygen: warning: %s revokes this credential (%s %s): the server refuses it until "
                   "that line is removed; issue it under another name instead\n",
                   path.c_str(), std::string(auth::RoleToString(c.role)).c_str(), c.name.c_str());
    }
  } catch (const auth::RevocationListError& e) {
    std::fprintf(stderr, "snapthread-keygen: warning: %s\n", e.what());
  }
}

void PrintFields(const auth::Credential& c, int64_t now_unix_s) {
  std::printf("  role     %s\n", std::string(auth::RoleToString(c.role)).c_str());
  if (!c.name.empty()) std::printf("  name     %s\n", c.name.c_str());
  std::printf("  key id   %s\n", auth::KeyIdToHex(c.key_id).c_str());
  std::printf("  root id  %s\n", auth::KeyIdToHex(c.root_id).c_str());
  std::printf("  server public key id  %s\n", auth::KeyIdToHex(auth::PublicKeyId(c.server_public_key)).c_str());
  std::printf("  expires  %s%s\n", ExpiryText(c.expires_unix_s).c_str(),
              c.ExpiredAt(now_unix_s) ? "  EXPIRED" : "");
  if (c.certificate) std::printf("  certificate  verifies with the server public key\n");
}

}  // namespace

int IssueRoleCredential(const KeygenOptions& o, const IssueRequest& request, int64_t now_unix_s) {
  const auth::KeyLocation where = auth::ResolveKeyPath(o.key_path);
  const auth::SessionKey root = auth::LoadKey(where);
  const auth::Credential issued = auth::IssueCredential(root, request.role, request.name, request.expires_unix_s);
  auth::WriteCredentialFile(o.out, issued, o.force);
  // Read back through every check (mode, owner, format, certificate), as its user will.
  const auth::Credential c = auth::LoadCredential(o.out);
  const std::string role(auth::RoleToString(c.role));
  std::printf("snapthread-keygen: wrote %s %s credential to %s (mode 0600), from the root key %s (%s)\n",
              c.role == Role::kDevice ? "a" : "an", role.c_str(), o.out.c_str(), where.path.c_str(),
              where.origin.c_str());
  PrintFields(c, now_unix_s);
  const std::string base = std::filesystem::path(o.out).filename().string();
  std::printf("Copy it to the %s's machine (scp -p keeps mode 0600):\n", role.c_str());
  std::printf("  ssh %s 'mkdir -p -m 700 ~/.config/snapthread'\n", o.host.c_str());
  std::printf("  scp -p %s %s:.config/snapthread/%s\n", o.out.c_str(), o.host.c_str(), base.c_str());
  std::printf("and start %s there with --key ~/.config/snapthread/%s\n", ProgramOf(c.role), base.c_str());
  WarnIfRevoked(where.path, c);
  return 0;
}

int ShowCredential(const KeygenOptions& o, int64_t now_unix_s) {
  const auth::Credential c = auth::LoadCredential(o.show);
  std::printf("%s: %s credential\n", o.show.c_str(), std::string(auth::RoleToString(c.role)).c_str());
  PrintFields(c, now_unix_s);
  return 0;
}

}  // namespace snapthread::keygen
