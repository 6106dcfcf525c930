#include "auth/key_file.h"

#include <pwd.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "auth/private_file.h"

namespace snapthread::auth {
namespace {

std::string HomeDir(const EnvLookup& env) {
  if (const char* home = env("HOME"); home != nullptr && home[0] != '\0') return home;
  std::vector<char> buf(16384);
  passwd pw{};
  passwd* found = nullptr;
  if (getpwuid_r(getuid(), &pw, buf.data(), buf.size(), &found) == 0 && found != nullptr &&
      found->pw_dir != nullptr && found->pw_dir[0] != '\0') {
    return found->pw_dir;
  }
  return "";
}

// The session key as a private file (auth/private_file.h): its name and fixes.
PrivateFileNaming KeyNaming(const KeyLocation& where) {
  return {
      .path = where.path,
      .named = "session key " + where.path + " (" + where.origin + ")",
      .thing = "key",
      .flag = "--key",
      .default_name = "session.key",
      .point_at = "point --key or SNAPTHREAD_KEY_FILE at the 32-byte key file made by snapthread-keygen",
      .make_command = "snapthread-keygen --key",
      .missing_message =
          "no session key at " + where.path + " (" + where.origin + ")" +
          ". Fix: make it with `snapthread-keygen --key " + ShellQuoted(where.path) +
          "` (or start snapthread-server once with --create-key), or copy the session's key here "
          "with scp -p; a missing key is never made silently (a typo would give a new key); see "
          "docs/security.md",
  };
}

// Runs `body`, turning the shared file rules' refusals into KeyFileError.
template <class Body>
auto AsKeyFileError(Body&& body) {
  try {
    return body();
  } catch (const PrivateFileError& e) {
    throw KeyFileError(e.what());
  }
}

}  // namespace

KeyLocation ResolveKeyPath(std::string_view flag_path) {
  return ResolveKeyPath(flag_path, [](const char* name) { return std::getenv(name); });
}

KeyLocation ResolveKeyPath(std::string_view flag_path, const EnvLookup& env) {
  if (!flag_path.empty()) return {std::string(flag_path), "--key"};
  if (const char* p = env(kKeyFileEnv); p != nullptr && p[0] != '\0') return {p, kKeyFileEnv};
  // XDG Base Directory: a relative XDG_CONFIG_HOME is invalid and ignored.
  if (const char* xdg = env("XDG_CONFIG_HOME"); xdg != nullptr && xdg[0] == '/') {
    return {std::string(xdg) + "/snapthread/session.key",
            "default: $XDG_CONFIG_HOME/snapthread/session.key"};
  }
  const std::string home = HomeDir(env);
  if (home.empty()) {
    throw KeyFileError(
        "no session key location: HOME and XDG_CONFIG_HOME are unset. Fix: pass --key FILE or "
        "set SNAPTHREAD_KEY_FILE");
  }
  return {home + "/.config/snapthread/session.key", "default: ~/.config/snapthread/session.key"};
}

SessionKey LoadKey(const KeyLocation& where) {
  const PrivateFileNaming file = KeyNaming(where);
  return AsKeyFileError([&] {
    const OpenedPrivateFile opened = OpenPrivateFile(file);
    if (opened.size != static_cast<off_t>(SessionKey::kBytes)) {
      throw KeyFileError(file.named + " holds " + std::to_string(opened.size) + " bytes; a key is " +
                         std::to_string(SessionKey::kBytes) + ". Fix: snapthread-keygen --force --key " +
                         ShellQuoted(where.path) + ", then copy the new key to every machine of the session");
    }
    uint8_t bytes[SessionKey::kBytes];
    try {
      ReadExactly(opened, file, bytes, sizeof bytes);
    } catch (...) {
      sodium_memzero(bytes, sizeof bytes);
      throw;
    }
    SessionKey key = SessionKey::FromBytes(bytes, SessionKey::kBytes);
    sodium_memzero(bytes, sizeof bytes);
    return key;
  });
}

LoadedKey LoadOrCreateKey(const KeyLocation& where) {
  struct stat st {};
  if (lstat(where.path.c_str(), &st) == 0 || errno != ENOENT) return {LoadKey(where), false};
  const PrivateFileNaming file = KeyNaming(where);
  AsKeyFileError([&] { PreparePrivateDir(file); });
  const SessionKey key = SessionKey::Generate();
  const std::string tmp =
      AsKeyFileError([&] { return WriteTempPrivateFile(file, key.data(), SessionKey::kBytes); });
  // link() fails when the name exists: a concurrent creator (another server starting)
  // wins and everyone uses its key.
  const int linked = link(tmp.c_str(), where.path.c_str());
  const int err = errno;
  unlink(tmp.c_str());
  if (linked != 0) {
    if (err == EEXIST) return {LoadKey(where), false};
    throw KeyFileError("cannot create " + file.named + ": " + std::strerror(err));
  }
  SyncDirOf(where.path);
  // Read back through every check (owner, mode, size), as any other start would.
  return {LoadKey(where), true};
}

void WriteNewKey(const KeyLocation& where, bool overwrite) {
  const PrivateFileNaming file = KeyNaming(where);
  const SessionKey key = SessionKey::Generate();
  const bool written = AsKeyFileError(
      [&] { return WritePrivateFile(file, key.data(), SessionKey::kBytes, overwrite); });
  if (!written) {
    throw KeyFileError("refusing to overwrite the existing " + file.named +
                       ": every machine of the session holds a copy. Fix: pass --force to "
                       "replace it, then copy the new key to every machine");
  }
}

}  // namespace snapthread::auth
