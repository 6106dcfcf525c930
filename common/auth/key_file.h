// Where the session key lives and how it is read and written (docs/security.md).
//
// Resolution order: `--key FILE` (the caller passes it), then the environment variable
// SNAPTHREAD_KEY_FILE, then $XDG_CONFIG_HOME/snapthread/session.key
// (~/.config/snapthread/session.key when XDG_CONFIG_HOME is unset or not absolute).
// A key file is refused unless it exists (nothing but snapthread-keygen or the server's
// --create-key makes one: a typo must not give a new key), is a regular file and not a
// symbolic link (opened with O_NOFOLLOW, checked with fstat on the opened descriptor), is
// owned by the user running snapthread, is exactly 32 bytes that neither group nor others
// may read or write (as ssh does for private keys), and sits in a directory that neither
// group nor others may write and that belongs to the user or root. Every refusal names
// the file and the fix (the rules every private file follows: auth/private_file.h). These
// run at start-up and throw KeyFileError.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "auth/session_key.h"

namespace snapthread::auth {

inline constexpr const char* kKeyFileEnv = "SNAPTHREAD_KEY_FILE";

// A key file that cannot be used; what() names the file and says how to fix it.
class KeyFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct KeyLocation {
  std::string path;
  // Where the path came from, for messages: "--key", "SNAPTHREAD_KEY_FILE",
  // "default: $XDG_CONFIG_HOME/snapthread/session.key" or "default: ~/.config/...".
  std::string origin;
};

// Environment lookup (getenv-like: nullptr when unset), replaceable in tests.
using EnvLookup = std::function<const char*(const char*)>;

// The key file to use. `flag_path` is the value of --key ("" when not given). Throws
// KeyFileError when no default can be formed (neither XDG_CONFIG_HOME nor a home dir).
KeyLocation ResolveKeyPath(std::string_view flag_path);
KeyLocation ResolveKeyPath(std::string_view flag_path, const EnvLookup& env);

// Reads the key at `where`; throws KeyFileError (missing, a symbolic link, a directory or
// not a regular file, another owner, group/other permissions, a writable or foreign
// directory, wrong size, unreadable).
SessionKey LoadKey(const KeyLocation& where);

struct LoadedKey {
  SessionKey key;
  bool created = false;  // true when this call made the file
};

// For the server's --create-key only: loads the key, or when the file does not exist
// creates it atomically (mode 0600, missing parent directories 0700; a concurrent creator
// wins and its key is loaded). An existing but unusable file is refused as LoadKey does,
// never replaced; an existing directory that LoadKey would refuse is refused first.
LoadedKey LoadOrCreateKey(const KeyLocation& where);

// For snapthread-keygen: writes a new random key to `where` atomically (mode 0600,
// parents 0700). Refuses an existing file unless `overwrite`, and a directory that
// LoadKey would refuse.
void WriteNewKey(const KeyLocation& where, bool overwrite);

}  // namespace snapthread::auth
