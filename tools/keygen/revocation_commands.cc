#include "revocation_commands.h"

#include <cstdio>
#include <filesystem>
#include <string>

#include "auth/key_file.h"
#include "auth/revocation_list.h"

namespace snapthread::keygen {
namespace {

bool Exists(const std::string& path) {
  return std::filesystem::exists(std::filesystem::symlink_status(path));
}

bool AlreadyRevoked(const auth::RevocationList& list, const RevokeRequest& request) {
  if (request.key_id) return list.key_ids().count(*request.key_id) != 0;
  for (const auto& [role, name] : list.names()) {
    if (role == *request.role && name == request.name) return true;
  }
  return false;
}

}  // namespace

int Revoke(const KeygenOptions& o, const RevokeRequest& request, int64_t now_unix_s) {
  const std::string path = RevokedPath(auth::ResolveKeyPath(o.key_path).path);
  if (Exists(path) && AlreadyRevoked(auth::RevocationList::Load(path), request)) {
    std::printf("snapthread-keygen: %s already revokes %s; nothing added\n", path.c_str(), request.entry.c_str());
  } else {
    const std::string lines = "# revoked " + ExpiryText(now_unix_s) + " by snapthread-keygen\n" + request.entry + "\n";
    const auth::RevocationList list = auth::RevocationList::Append(path, lines);
    std::printf("snapthread-keygen: revoked %s in %s (mode 0600, %zu %s)\n", request.entry.c_str(),
                path.c_str(), list.size(), list.size() == 1 ? "entry" : "entries");
  }
  std::printf("Next step: make the running server read it (it reads %s at start and on SIGHUP):\n", path.c_str());
  std::printf("  kill -HUP $(pidof snapthread-server)\n");
  if (request.key_id) {
    std::printf("From then on the server refuses every message made with key id %s.\n", request.entry.c_str() + 7);
  } else {
    std::printf("From then on the server refuses every message of %s, whatever its credential's expiry: a\n"
                "re-issued credential needs another name (or this line removed from %s).\n",
                request.entry.c_str(), path.c_str());
  }
  return 0;
}

int ListRevoked(const KeygenOptions& o) {
  const std::string path = RevokedPath(auth::ResolveKeyPath(o.key_path).path);
  if (!Exists(path)) {
    std::printf("%s: no such file: nothing is revoked\n", path.c_str());
    return 0;
  }
  const auth::RevocationList list = auth::RevocationList::Load(path);
  std::printf("%s: %zu %s\n", path.c_str(), list.size(), list.size() == 1 ? "entry" : "entries");
  for (const auto& [role, name] : list.names()) {
    std::printf("  %s %s\n", std::string(auth::RoleToString(role)).c_str(), name.c_str());
  }
  for (const auth::KeyId& id : list.key_ids()) std::printf("  key_id %s\n", auth::KeyIdToHex(id).c_str());
  return 0;
}

}  // namespace snapthread::keygen
