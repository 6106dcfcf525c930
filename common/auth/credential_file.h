// A credential on disk: the same rules as the session key file (auth/private_file.h:
// it exists, is a regular file and no symbolic link, is the user's own, mode 0600 or
// 0400, in a directory only the user or root may write), at most kMaxCredentialFileBytes
// of the text form of auth/credential.h. Every refusal is a CredentialError naming the
// file and the fix.
#pragma once

#include <cstddef>
#include <string>

#include "auth/credential.h"

namespace snapthread::auth {

inline constexpr std::size_t kMaxCredentialFileBytes = 4096;

// Writes `credential` to `path` atomically (mode 0600, missing parents 0700). Refuses an
// existing file unless `overwrite`.
void WriteCredentialFile(const std::string& path, const Credential& credential, bool overwrite);

// Reads and parses the credential at `path` (it does not look at the clock: the caller
// checks ExpiredAt and RequireRole).
Credential LoadCredential(const std::string& path);

}  // namespace snapthread::auth
