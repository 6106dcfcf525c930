// snapthread-keygen's root key modes: making the root key (the session key file, kept on
// the server host), printing its id (--id), and rotating it (--rotate).
#pragma once

#include "keygen_options.h"

namespace snapthread::keygen {

// Writes a new root key at --key (an existing one only with --force) and prints how to
// copy it, as snapthread-keygen always has.
int MakeRootKey(const KeygenOptions& options);

// Checks the root key at --key and prints its id.
int ShowRootKeyId(const KeygenOptions& options);

// Moves the root key FILE to FILE.previous (replacing an older one), writes a new root
// key at FILE and prints both ids and the next steps. FILE exists throughout: the old key
// is first written to FILE.previous, then the new one replaces FILE atomically, so a
// server reloading meanwhile reads a whole key.
int RotateRootKey(const KeygenOptions& options);

}  // namespace snapthread::keygen
