// The rules every private file of a session follows (the session key, a role credential,
// a revocation list; docs/security.md "Key handling"), in one place so that each kind of
// file is refused for the same reasons with the same fixes.
//
// A private file is read only when it exists (nothing makes one silently: a typo must not
// give a new key), is a regular file and not a symbolic link (opened with O_NOFOLLOW
// relative to its already opened directory, checked with fstat on the opened descriptor:
// what is checked is what is read), is owned by the user running snapthread, grants group
// and others nothing (as ssh does for private keys), and sits in a directory that neither
// group nor others may write and that belongs to the user or root. It is written through a
// temporary file (mkstemp: O_EXCL, mode 0600) linked or renamed into place, so no reader
// ever sees half a file. Every refusal names the file and says how to fix it.
#pragma once

#include <sys/stat.h>
#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace snapthread::auth {

// A private file that cannot be used; what() names the file and says how to fix it. The
// callers rethrow it as their own error type (KeyFileError, CredentialError).
class PrivateFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// How a kind of private file is named in the messages and how its refusals are fixed.
struct PrivateFileNaming {
  std::string path;
  std::string named;           // "session key /x/session.key (--key)"
  std::string thing;           // what another user could replace: "key", "credential"
  std::string flag;            // the option that names the file: "--key"
  std::string default_name;    // a file name to suggest for a directory: "session.key"
  std::string point_at;        // fix for a FIFO etc.: "point --key ... at the 32-byte key ..."
  std::string make_command;    // makes a new one given a path: "snapthread-keygen --key"
  std::string missing_message; // the whole refusal of a missing file
};

// An open descriptor, closed on destruction.
class UniqueFd {
 public:
  explicit UniqueFd(int fd = -1) : fd_(fd) {}
  UniqueFd(UniqueFd&& other) noexcept;
  UniqueFd& operator=(UniqueFd&& other) noexcept;
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  ~UniqueFd();
  int get() const { return fd_; }

 private:
  int fd_;
};

struct OpenedPrivateFile {
  UniqueFd fd;
  off_t size = 0;
};

// Opens the file under the rules above; throws PrivateFileError otherwise.
OpenedPrivateFile OpenPrivateFile(const PrivateFileNaming& file);

// Reads exactly `size` bytes of an opened file into `out`; throws PrivateFileError when it
// cannot, or when the file no longer has that size (changed while being read).
void ReadExactly(const OpenedPrivateFile& opened, const PrivateFileNaming& file, uint8_t* out,
                 std::size_t size);

// The refusal of a directory that group or others may write, or that belongs to someone
// other than the user or root (they could rename another file over ours). `st` is the
// directory's stat.
void CheckPrivateDir(const std::string& dir, const struct stat& st, const PrivateFileNaming& file);

// Before a file is written: creates its missing parent directories (mode 0700) and checks
// its directory as CheckPrivateDir does.
void PreparePrivateDir(const PrivateFileNaming& file);

// Writes `size` bytes to `file.path` atomically with mode 0600 (PreparePrivateDir first).
// An existing file is replaced only when `overwrite`; otherwise it is kept and the call
// returns false (the caller words that refusal). Throws PrivateFileError on the rest.
[[nodiscard]] bool WritePrivateFile(const PrivateFileNaming& file, const uint8_t* bytes,
                                    std::size_t size, bool overwrite);

// Writes `size` bytes to a new temporary file (mode 0600) next to `file.path`, fsynced,
// and returns its path, for a caller that links it into place itself.
std::string WriteTempPrivateFile(const PrivateFileNaming& file, const uint8_t* bytes,
                                 std::size_t size);

// fsyncs the directory holding `file` (after a link or rename).
void SyncDirOf(const std::string& file);

// The directory holding `file` ("." for a bare name).
std::string DirOf(const std::string& file);

// A path as it can be pasted into a shell command of a message.
std::string ShellQuoted(const std::string& s);

// A user's name for messages ("uid 65534" when unknown).
std::string UserName(uid_t uid);

// "0644": a mode for messages.
std::string ModeString(mode_t mode);

}  // namespace snapthread::auth
