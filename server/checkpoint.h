// The server's checkpoint: what a restarted server needs to resume on
// the branch the hand was feeling — the scene (its text, so it reloads even when the
// file changed or came from LOAD_SCENE), the method, the grasp u and the state x — in one
// file written atomically.
//
// File layout (integers little-endian, doubles IEEE-754 binary64 little-endian):
//   header   "SNAPCKPT" | u32 version (1) | u32 payload length P
//   payload  i64 utime (CLOCK_REALTIME µs when taken) | i64 epoch of the writing server |
//            i64 seq (checkpoints that server took) |
//            str scene name | str scene file | str scene text | str method |
//            u32 m, m x f64 u | u32 n, n x f64 x          (str = u32 length + bytes)
//   trailer  32-byte BLAKE2b-256 checksum of header + payload |
//            32-byte crypto_auth tag (session key, domain "checkpoint") of all before it
// The checksum tells a torn or damaged file; the tag tells an intact file that a holder
// of the session key did not write (docs/security.md "Checkpoints").
//
// Writing (WriteFileAtomically): <file>.tmp in the same directory, write, fsync the file,
// rename over <file>, fsync the directory. A crash at any point leaves either the
// previous checkpoint or the new one, never a mix.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include "auth/session_key.h"
#include "numeric/types.h"

namespace snapthread::server {

struct Checkpoint {
  int64_t utime = 0;  // wall clock when taken, µs
  int64_t epoch = 0;  // the epoch of the server that wrote it (for the log only)
  int64_t seq = 0;    // the how-many-th checkpoint of that server
  std::string scene_name;
  std::string scene_file;  // where that server loaded the scene from (a label)
  std::string scene_text;  // the scene's YAML as loaded
  std::string method;      // the tracker's method
  Vec u;                   // grasp (model controls)
  Vec x;                   // equilibrium state on the branch being followed
};

inline constexpr uint32_t kCheckpointVersion = 1;
inline constexpr size_t kCheckpointHeaderBytes = 16;
inline constexpr size_t kCheckpointTrailerBytes = 64;
// Larger files are refused unread (a scene is at most a few MiB; a state of 10^6 doubles).
inline constexpr size_t kMaxCheckpointBytes = 64u << 20;

// The file's bytes. Never fails for a finite checkpoint; the caller writes only finite
// states (Decode refuses non-finite ones).
std::string EncodeCheckpoint(const Checkpoint& c, const auth::SessionKey& key);

// Checks and decodes a file's bytes. False with *reason (one phrase, no file name) for:
// a truncated file, bad magic, another version, a length that is not the header's,
// a checksum mismatch, a tag not made with `key`, a malformed payload, a non-finite value
// in u or x. Never throws.
bool DecodeCheckpoint(const std::string& bytes, const auth::SessionKey& key, Checkpoint* out,
                      std::string* reason);

// The checkpoint file of a session in a --state-dir: DIR/<session>.checkpoint.
std::string CheckpointPath(const std::string& state_dir, const std::string& session);

// The file or its directory cannot be used (the message names the path and the cause).
class CheckpointIoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Makes DIR (mode 0700) when it does not exist; throws CheckpointIoError when it exists
// but is not a writable directory, or cannot be made.
void PrepareStateDir(const std::string& dir);

// The two halves of WriteFileAtomically, apart so a test can stop between them (a crash
// after the write, before the rename). WriteTempFile writes and fsyncs path + ".tmp";
// CommitTempFile renames it over path and fsyncs the directory. Both throw
// CheckpointIoError.
void WriteTempFile(const std::string& path, const std::string& bytes);
void CommitTempFile(const std::string& path);
void WriteFileAtomically(const std::string& path, const std::string& bytes);

enum class ReadStatus { kOk, kMissing, kRefused };
// Reads a checkpoint file: a regular file (no symlink) of at most kMaxCheckpointBytes.
// kMissing when it does not exist; kRefused with *reason otherwise when it cannot be read.
ReadStatus ReadCheckpointFile(const std::string& path, std::string* bytes, std::string* reason);

}  // namespace snapthread::server
