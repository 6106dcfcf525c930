// snapthread-keygen's revocation modes: --revoke NAME / --revoke-key-id HEX16 append a line
// to FILE.revoked beside the root key FILE (auth/revocation_list.h), which the server reads
// at start and on SIGHUP; --list-revoked prints what it holds.
#pragma once

#include <cstdint>

#include "keygen_options.h"

namespace snapthread::keygen {

// Appends `request`'s entry (with a dated comment) to FILE.revoked, creating it mode 0600
// when missing; an existing list that does not load is refused and left as it is. Prints
// the entry and the next step (kill -HUP the server).
int Revoke(const KeygenOptions& options, const RevokeRequest& request, int64_t now_unix_s);

// Prints the entries of FILE.revoked ("nothing is revoked" when there is none).
int ListRevoked(const KeygenOptions& options);

}  // namespace snapthread::keygen
