#include "root_key_commands.h"

#include <cstdio>
#include <string>

#include "auth/key_file.h"
#include "auth/private_file.h"

namespace snapthread::keygen {

int MakeRootKey(const KeygenOptions& o) {
  const auth::KeyLocation where = auth::ResolveKeyPath(o.key_path);
  auth::WriteNewKey(where, o.force);
  const std::string id = auth::LoadKey(where).Id();  // reads it back: mode and size as checked
  std::printf("snapthread-keygen: wrote a new session key to %s (mode 0600, key id %s)\n", where.path.c_str(),
              id.c_str());
  std::printf("Copy it to the other machine (scp -p keeps mode 0600):\n");
  std::printf("  ssh %s 'mkdir -p -m 700 ~/.config/snapthread'\n", o.host.c_str());
  std::printf("  scp -p %s %s:.config/snapthread/session.key\n", where.path.c_str(), o.host.c_str());
  std::printf("Check the copy: ssh %s snapthread-keygen --id   (must print key id %s)\n", o.host.c_str(), id.c_str());
  std::printf("Or keep it on this host only and give each machine its role's credential:\n");
  std::printf("  snapthread-keygen --key %s --role device --device hand --out hand.cred   (see --help)\n",
              auth::ShellQuoted(where.path).c_str());
  return 0;
}

int ShowRootKeyId(const KeygenOptions& o) {
  const auth::KeyLocation where = auth::ResolveKeyPath(o.key_path);
  std::printf("%s: key id %s (%s)\n", where.path.c_str(), auth::LoadKey(where).Id().c_str(), where.origin.c_str());
  return 0;
}

int RotateRootKey(const KeygenOptions& o) {
  const auth::KeyLocation where = auth::ResolveKeyPath(o.key_path);
  const auth::SessionKey old_root = auth::LoadKey(where);  // refused as every start refuses it
  const auth::KeyLocation previous{PreviousPath(where.path), "the previous root key of " + where.path};
  // The key file's rules for FILE.previous: the same directory, mode 0600, written whole.
  const auth::PrivateFileNaming previous_file{
      .path = previous.path,
      .named = "previous root key " + previous.path,
      .thing = "key",
      .flag = "--key",
      .default_name = "session.key.previous",
      .point_at = "remove it: snapthread-keygen --rotate writes it",
      .make_command = "snapthread-keygen --rotate --key",
      .missing_message = "",
  };
  try {
    const bool written = auth::WritePrivateFile(previous_file, old_root.data(), auth::SessionKey::kBytes, true);
    (void)written;  // always, with overwrite
  } catch (const auth::PrivateFileError& e) {
    throw auth::KeyFileError(e.what());
  }
  auth::WriteNewKey(where, true);
  const std::string old_id = auth::LoadKey(previous).Id();
  const std::string new_id = auth::LoadKey(where).Id();
  const std::string key = auth::ShellQuoted(where.path);
  std::printf("snapthread-keygen: rotated the root key %s\n", where.path.c_str());
  std::printf("  previous key id %s, now in %s\n", old_id.c_str(), previous.path.c_str());
  std::printf("  new key id      %s, in %s (mode 0600)\n", new_id.c_str(), where.path.c_str());
  std::printf("Next steps:\n");
  std::printf("  1. issue every credential again from the new key:\n");
  std::printf("       snapthread-keygen --key %s --role device --device NAME --out NAME.cred --force\n", key.c_str());
  std::printf("       (and --role operator --name NAME, --role observer, with the same --expires as before)\n");
  std::printf("  2. make the server load it: kill -HUP $(pidof snapthread-server)\n");
  std::printf("     it then accepts the previous key for its --key-grace-s (default 60 s)\n");
  std::printf("  3. within that grace, copy each credential (scp -p NAME.cred %s:.config/snapthread/) and\n",
              o.host.c_str());
  std::printf("     kill -HUP each device (kill -HUP $(pidof snapthread-device)) so it loads it; restart each\n");
  std::printf("     viewer, web bridge and snapthread-ctl on its new credential (they read it at start)\n");
  return 0;
}

}  // namespace snapthread::keygen
