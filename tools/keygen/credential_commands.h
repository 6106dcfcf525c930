// snapthread-keygen's credential modes: --role issues a role's credential from the root
// key; --show prints what a credential holds, without its secrets.
#pragma once

#include <cstdint>

#include "keygen_options.h"

namespace snapthread::keygen {

// Writes the credential of `request` (IssueCredential from the root key of --key,
// WriteCredentialFile: mode 0600, an existing file only with --force) and prints the file,
// role, name, key id, expiry and how to copy it. Returns the exit code; throws on failure.
int IssueRoleCredential(const KeygenOptions& options, const IssueRequest& request, int64_t now_unix_s);

// Prints --show FILE's role, name, expiry, ids and whether it is expired.
int ShowCredential(const KeygenOptions& options, int64_t now_unix_s);

}  // namespace snapthread::keygen
