#include "auth/key_file.h"

#include <fcntl.h>
#include <pwd.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

namespace snapthread::auth {
namespace {

std::string Errno(int err) { return std::strerror(err); }

// A path as it can be pasted into a shell command of a message.
std::string ShellQuoted(const std::string& s) {
  bool plain = !s.empty();
  for (char c : s) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || std::strchr("/._-+~:@%,=", c) != nullptr)) {
      plain = false;
    }
  }
  if (plain) return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string Named(const KeyLocation& where) {
  return "session key " + where.path + " (" + where.origin + ")";
}

// The refusal of a directory, FIFO, device or socket where the key file should be.
KeyFileError NotAKeyFile(const KeyLocation& where, mode_t mode) {
  if (S_ISDIR(mode)) {
    return KeyFileError(Named(where) + " is a directory. Fix: pass the key file itself, e.g. --key " +
                        ShellQuoted(where.path + "/session.key"));
  }
  return KeyFileError(Named(where) +
                      " is not a regular file (a FIFO, device or socket). Fix: point --key or "
                      "SNAPTHREAD_KEY_FILE at the 32-byte key file made by snapthread-keygen");
}

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

// The directory holding `file` ("." for a bare name).
std::string DirOf(const std::string& file) {
  const std::filesystem::path parent = std::filesystem::path(file).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd_ >= 0) close(fd_);
  }
  int get() const { return fd_; }

 private:
  int fd_;
};

// Creates the missing directories above `file` with mode 0700 (existing ones are left
// as they are).
void MakeParentDirs(const std::string& file) {
  const std::filesystem::path parent = std::filesystem::path(file).parent_path();
  std::filesystem::path prefix;
  for (const auto& part : parent) {
    prefix /= part;
    if (mkdir(prefix.c_str(), 0700) == 0) continue;
    const int err = errno;
    struct stat st {};
    if (err == EEXIST && stat(prefix.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) continue;
    throw KeyFileError("cannot create the directory " + prefix.string() + " for the session key " +
                       file + ": " + Errno(err == EEXIST ? ENOTDIR : err));
  }
}

void SyncDir(const std::string& file) {
  const std::string dir = DirOf(file);
  const Fd fd(open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (fd.get() >= 0) fsync(fd.get());
}

// Writes `key` to a new temporary file (mkstemp: O_EXCL, mode 0600) next to `file` and
// returns its path; the caller links or renames it into place, so no reader ever sees a
// partly written key.
std::string WriteTempKey(const std::string& file, const SessionKey& key) {
  const std::string dir = DirOf(file);
  std::string tmp = dir + "/.session.key.XXXXXX";
  const Fd fd(mkstemp(tmp.data()));
  if (fd.get() < 0) {
    throw KeyFileError("cannot create a session key file in " + dir + ": " + Errno(errno));
  }
  auto fail = [&](const std::string& what) {
    const int err = errno;
    unlink(tmp.c_str());
    throw KeyFileError("cannot write the session key " + file + " (" + what + "): " + Errno(err));
  };
  if (fchmod(fd.get(), 0600) != 0) fail("chmod");
  std::size_t done = 0;
  while (done < SessionKey::kBytes) {
    const ssize_t n = write(fd.get(), key.data() + done, SessionKey::kBytes - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("write");
    done += static_cast<std::size_t>(n);
  }
  if (fsync(fd.get()) != 0) fail("fsync");
  return tmp;
}

// "uid 65534 (nobody)": an owner for messages.
std::string UserName(uid_t uid) {
  std::vector<char> buf(16384);
  passwd pw{};
  passwd* found = nullptr;
  std::string name = "uid " + std::to_string(uid);
  if (getpwuid_r(uid, &pw, buf.data(), buf.size(), &found) == 0 && found != nullptr &&
      found->pw_name != nullptr) {
    return found->pw_name;
  }
  return name;
}

KeyFileError MissingKey(const KeyLocation& where) {
  return KeyFileError("no session key at " + where.path + " (" + where.origin + ")" +
                      ". Fix: make it with `snapthread-keygen --key " + ShellQuoted(where.path) +
                      "` (or start snapthread-server once with --create-key), or copy the "
                      "session's key here with scp -p; a missing key is never made silently "
                      "(a typo would give a new key); see docs/security.md");
}

KeyFileError Symlink(const KeyLocation& where) {
  std::error_code ec;
  const std::filesystem::path real = std::filesystem::canonical(where.path, ec);
  std::string fix = ": --key " + ShellQuoted(real.string());
  if (ec) {
    std::error_code ec2;
    const std::filesystem::path target = std::filesystem::read_symlink(where.path, ec2);
    fix = ec2 ? std::string(" of the key file")
              : " of the key file (this link points to " + target.string() +
                    ", which does not exist)";
  }
  return KeyFileError(Named(where) + " is a symbolic link, so it is refused (whoever can change "
                      "the link would choose the key). Fix: use the real path" + fix);
}

// The directory holding a key: writable by group or others, or owned by someone other
// than the user or root, lets another user replace the key (rename over it).
void CheckKeyDir(const std::string& dir, const struct stat& st, const std::string& what) {
  if ((st.st_mode & 022) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    // A shared directory such as /tmp (sticky, or not the user's) must stay writable for
    // the others: the key moves instead.
    const bool shared = (st.st_mode & S_ISVTX) != 0 || st.st_uid != geteuid();
    throw KeyFileError("the directory " + dir + " of " + what + " has mode " + mode +
                       ": group or others may write to it and replace the key, so it is "
                       "refused. Fix: " +
                       (shared ? "keep the key in a directory of your own (mkdir -m 700 DIR, "
                                 "then snapthread-keygen --key DIR/session.key)"
                               : "chmod go-w " + ShellQuoted(dir) +
                                     " (or keep the key in a directory of mode 0700)"));
  }
  if (st.st_uid != geteuid() && st.st_uid != 0) {
    throw KeyFileError("the directory " + dir + " of " + what + " is owned by " +
                       UserName(st.st_uid) + ", who could replace the key, so it is refused. "
                       "Fix: chown " + UserName(geteuid()) + " " + ShellQuoted(dir) +
                       " (as root), or keep the key in a directory of your own");
  }
}

// Before a key is written: its directory (made 0700 when missing) must pass CheckKeyDir.
void CheckExistingKeyDir(const KeyLocation& where) {
  const std::string dir = DirOf(where.path);
  struct stat st {};
  if (stat(dir.c_str(), &st) == 0) CheckKeyDir(dir, st, "the " + Named(where));
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
  const std::string& path = where.path;
  const std::string q = ShellQuoted(path);
  const std::string dir = DirOf(path);
  const std::string base = std::filesystem::path(path).filename().string();
  // The directory first, then the file relative to that very directory (openat) and its
  // fstat on the opened descriptor: what is checked is what is read (no TOCTOU).
  const Fd dir_fd(open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (dir_fd.get() < 0 && errno == ENOENT) throw MissingKey(where);
  if (dir_fd.get() < 0) {
    throw KeyFileError("cannot open the directory " + dir + " of the " + Named(where) + ": " +
                       Errno(errno) + ". Fix: the directory must be searchable by the user "
                       "running snapthread (chown, then chmod 700 " + ShellQuoted(dir) + ")");
  }
  // O_NOFOLLOW: a symbolic link is refused (ELOOP), not followed: whoever can change the
  // link would choose the key. O_NONBLOCK: opening a FIFO must not wait for a writer (it
  // is refused below).
  const Fd fd(base.empty() ? -1
                           : openat(dir_fd.get(), base.c_str(),
                                    O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK | O_NOFOLLOW));
  if (fd.get() < 0) {
    const int err = base.empty() ? ENOENT : errno;
    if (err == ENOENT) throw MissingKey(where);
    struct stat lst {};
    if (err == ELOOP && fstatat(dir_fd.get(), base.c_str(), &lst, AT_SYMLINK_NOFOLLOW) == 0 &&
        S_ISLNK(lst.st_mode)) {
      throw Symlink(where);
    }
    throw KeyFileError("cannot open " + Named(where) + ": " + Errno(err) +
                       ". Fix: the key must be readable by the user running snapthread (chown, "
                       "then chmod 0600 " + q + ")");
  }
  struct stat st {};
  if (fstat(fd.get(), &st) != 0) {
    throw KeyFileError("cannot stat " + Named(where) + ": " + Errno(errno));
  }
  if (!S_ISREG(st.st_mode)) throw NotAKeyFile(where, st.st_mode);
  struct stat dst {};
  if (fstat(dir_fd.get(), &dst) != 0) {
    throw KeyFileError("cannot stat the directory " + dir + ": " + Errno(errno));
  }
  CheckKeyDir(dir, dst, "the " + Named(where));
  if (st.st_uid != geteuid()) {
    throw KeyFileError(Named(where) + " is owned by " + UserName(st.st_uid) + ", not by " +
                       UserName(geteuid()) + " who runs snapthread, so it is refused (its owner "
                       "could change it). Fix: chown " + UserName(geteuid()) + " " + q +
                       " (as root), or run snapthread as its owner");
  }
  if ((st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    throw KeyFileError(Named(where) + " has mode " + mode +
                       ": group or others may read or write it, so it is refused. Fix: chmod 0600 " + q);
  }
  if (st.st_size != static_cast<off_t>(SessionKey::kBytes)) {
    throw KeyFileError(Named(where) + " holds " + std::to_string(st.st_size) + " bytes; a key is " +
                       std::to_string(SessionKey::kBytes) +
                       ". Fix: snapthread-keygen --force --key " + q +
                       ", then copy the new key to every machine of the session");
  }
  uint8_t bytes[SessionKey::kBytes + 1];
  std::size_t got = 0;
  while (got < sizeof bytes) {
    const ssize_t n = read(fd.get(), bytes + got, sizeof bytes - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      sodium_memzero(bytes, sizeof bytes);
      throw KeyFileError("cannot read " + Named(where) + ": " + Errno(err));
    }
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  if (got != SessionKey::kBytes) {  // changed size while being read
    sodium_memzero(bytes, sizeof bytes);
    throw KeyFileError(Named(where) + " changed while it was read (" + std::to_string(got) +
                       " bytes). Fix: retry once the file is written");
  }
  SessionKey key = SessionKey::FromBytes(bytes, SessionKey::kBytes);
  sodium_memzero(bytes, sizeof bytes);
  return key;
}

LoadedKey LoadOrCreateKey(const KeyLocation& where) {
  struct stat st {};
  if (lstat(where.path.c_str(), &st) == 0 || errno != ENOENT) return {LoadKey(where), false};
  MakeParentDirs(where.path);
  CheckExistingKeyDir(where);
  SessionKey key = SessionKey::Generate();
  const std::string tmp = WriteTempKey(where.path, key);
  // link() fails when the name exists: a concurrent creator (another server starting)
  // wins and everyone uses its key.
  const int linked = link(tmp.c_str(), where.path.c_str());
  const int err = errno;
  unlink(tmp.c_str());
  if (linked != 0) {
    if (err == EEXIST) return {LoadKey(where), false};
    throw KeyFileError("cannot create " + Named(where) + ": " + Errno(err));
  }
  SyncDir(where.path);
  // Read back through every check (owner, mode, size), as any other start would.
  return {LoadKey(where), true};
}

void WriteNewKey(const KeyLocation& where, bool overwrite) {
  MakeParentDirs(where.path);
  CheckExistingKeyDir(where);
  const SessionKey key = SessionKey::Generate();
  const std::string tmp = WriteTempKey(where.path, key);
  const int done = overwrite ? rename(tmp.c_str(), where.path.c_str())
                             : link(tmp.c_str(), where.path.c_str());
  const int err = errno;
  if (!overwrite || done != 0) unlink(tmp.c_str());
  if (done != 0) {
    // A directory or a device in the key's place is no key to keep: say what it is.
    struct stat st {};
    if (lstat(where.path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) throw NotAKeyFile(where, st.st_mode);
    if (err == EEXIST) {
      throw KeyFileError("refusing to overwrite the existing " + Named(where) +
                         ": every machine of the session holds a copy. Fix: pass --force to "
                         "replace it, then copy the new key to every machine");
    }
    throw KeyFileError("cannot write " + Named(where) + ": " + Errno(err));
  }
  SyncDir(where.path);
}

}  // namespace snapthread::auth
