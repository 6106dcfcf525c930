#include "auth/private_file.h"

#include <fcntl.h>
#include <pwd.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <utility>
#include <vector>

namespace snapthread::auth {
namespace {

std::string Errno(int err) { return std::strerror(err); }

// The refusal of a directory, FIFO, device or socket where the file should be.
PrivateFileError NotAFile(const PrivateFileNaming& file, mode_t mode) {
  if (S_ISDIR(mode)) {
    return PrivateFileError(file.named + " is a directory. Fix: pass the " + file.thing +
                            " file itself, e.g. " + file.flag + " " +
                            ShellQuoted(file.path + "/" + file.default_name));
  }
  return PrivateFileError(file.named + " is not a regular file (a FIFO, device or socket). Fix: " +
                          file.point_at);
}

PrivateFileError Symlink(const PrivateFileNaming& file) {
  std::error_code ec;
  const std::filesystem::path real = std::filesystem::canonical(file.path, ec);
  std::string fix = ": " + file.flag + " " + ShellQuoted(real.string());
  if (ec) {
    std::error_code ec2;
    const std::filesystem::path target = std::filesystem::read_symlink(file.path, ec2);
    fix = ec2 ? " of the " + file.thing + " file"
              : " of the " + file.thing + " file (this link points to " + target.string() +
                    ", which does not exist)";
  }
  return PrivateFileError(file.named + " is a symbolic link, so it is refused (whoever can "
                          "change the link would choose the " + file.thing +
                          "). Fix: use the real path" + fix);
}

// Creates the missing directories above `path` with mode 0700 (existing ones are left
// as they are).
void MakeParentDirs(const PrivateFileNaming& file) {
  const std::filesystem::path parent = std::filesystem::path(file.path).parent_path();
  std::filesystem::path prefix;
  for (const auto& part : parent) {
    prefix /= part;
    if (mkdir(prefix.c_str(), 0700) == 0) continue;
    const int err = errno;
    struct stat st {};
    if (err == EEXIST && stat(prefix.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) continue;
    throw PrivateFileError("cannot create the directory " + prefix.string() + " for the " +
                           file.named + ": " + Errno(err == EEXIST ? ENOTDIR : err));
  }
}

}  // namespace

UniqueFd::UniqueFd(UniqueFd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}

UniqueFd& UniqueFd::operator=(UniqueFd&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) close(fd_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

UniqueFd::~UniqueFd() {
  if (fd_ >= 0) close(fd_);
}

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

std::string DirOf(const std::string& file) {
  const std::filesystem::path parent = std::filesystem::path(file).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

std::string UserName(uid_t uid) {
  std::vector<char> buf(16384);
  passwd pw{};
  passwd* found = nullptr;
  if (getpwuid_r(uid, &pw, buf.data(), buf.size(), &found) == 0 && found != nullptr &&
      found->pw_name != nullptr) {
    return found->pw_name;
  }
  return "uid " + std::to_string(uid);
}

std::string ModeString(mode_t mode) {
  char text[8];
  std::snprintf(text, sizeof text, "%04o", static_cast<unsigned>(mode & 07777));
  return text;
}

void CheckPrivateDir(const std::string& dir, const struct stat& st, const PrivateFileNaming& file) {
  const std::string what = "the " + file.named;
  if ((st.st_mode & 022) != 0) {
    // A shared directory such as /tmp (sticky, or not the user's) must stay writable for
    // the others: the file moves instead.
    const bool shared = (st.st_mode & S_ISVTX) != 0 || st.st_uid != geteuid();
    throw PrivateFileError(
        "the directory " + dir + " of " + what + " has mode " + ModeString(st.st_mode) +
        ": group or others may write to it and replace the " + file.thing +
        ", so it is refused. Fix: " +
        (shared ? "keep the " + file.thing + " in a directory of your own (mkdir -m 700 DIR, then " +
                      file.make_command + " DIR/" + file.default_name + ")"
                : "chmod go-w " + ShellQuoted(dir) + " (or keep the " + file.thing +
                      " in a directory of mode 0700)"));
  }
  if (st.st_uid != geteuid() && st.st_uid != 0) {
    throw PrivateFileError("the directory " + dir + " of " + what + " is owned by " +
                           UserName(st.st_uid) + ", who could replace the " + file.thing +
                           ", so it is refused. Fix: chown " + UserName(geteuid()) + " " +
                           ShellQuoted(dir) + " (as root), or keep the " + file.thing +
                           " in a directory of your own");
  }
}

OpenedPrivateFile OpenPrivateFile(const PrivateFileNaming& file) {
  const std::string& path = file.path;
  const std::string dir = DirOf(path);
  const std::string base = std::filesystem::path(path).filename().string();
  // The directory first, then the file relative to that very directory (openat) and its
  // fstat on the opened descriptor: what is checked is what is read (no TOCTOU).
  const UniqueFd dir_fd(open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (dir_fd.get() < 0 && errno == ENOENT) throw PrivateFileError(file.missing_message);
  if (dir_fd.get() < 0) {
    throw PrivateFileError("cannot open the directory " + dir + " of the " + file.named + ": " +
                           Errno(errno) + ". Fix: the directory must be searchable by the user "
                           "running snapthread (chown, then chmod 700 " + ShellQuoted(dir) + ")");
  }
  // O_NOFOLLOW: a symbolic link is refused (ELOOP), not followed. O_NONBLOCK: opening a
  // FIFO must not wait for a writer (it is refused below).
  OpenedPrivateFile opened;
  opened.fd = UniqueFd(base.empty() ? -1
                                    : openat(dir_fd.get(), base.c_str(),
                                             O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK | O_NOFOLLOW));
  if (opened.fd.get() < 0) {
    const int err = base.empty() ? ENOENT : errno;
    if (err == ENOENT) throw PrivateFileError(file.missing_message);
    struct stat lst {};
    if (err == ELOOP && fstatat(dir_fd.get(), base.c_str(), &lst, AT_SYMLINK_NOFOLLOW) == 0 &&
        S_ISLNK(lst.st_mode)) {
      throw Symlink(file);
    }
    throw PrivateFileError("cannot open " + file.named + ": " + Errno(err) + ". Fix: the " +
                           file.thing + " must be readable by the user running snapthread "
                           "(chown, then chmod 0600 " + ShellQuoted(path) + ")");
  }
  struct stat st {};
  if (fstat(opened.fd.get(), &st) != 0) {
    throw PrivateFileError("cannot stat " + file.named + ": " + Errno(errno));
  }
  if (!S_ISREG(st.st_mode)) throw NotAFile(file, st.st_mode);
  struct stat dst {};
  if (fstat(dir_fd.get(), &dst) != 0) {
    throw PrivateFileError("cannot stat the directory " + dir + ": " + Errno(errno));
  }
  CheckPrivateDir(dir, dst, file);
  if (st.st_uid != geteuid()) {
    throw PrivateFileError(file.named + " is owned by " + UserName(st.st_uid) + ", not by " +
                           UserName(geteuid()) + " who runs snapthread, so it is refused (its "
                           "owner could change it). Fix: chown " + UserName(geteuid()) + " " +
                           ShellQuoted(path) + " (as root), or run snapthread as its owner");
  }
  if ((st.st_mode & 077) != 0) {
    throw PrivateFileError(file.named + " has mode " + ModeString(st.st_mode) +
                           ": group or others may read or write it, so it is refused. Fix: "
                           "chmod 0600 " + ShellQuoted(path));
  }
  opened.size = st.st_size;
  return opened;
}

void ReadExactly(const OpenedPrivateFile& opened, const PrivateFileNaming& file, uint8_t* out,
                 std::size_t size) {
  std::size_t got = 0;
  uint8_t extra = 0;
  for (;;) {
    uint8_t* dst = got < size ? out + got : &extra;
    const std::size_t want = got < size ? size - got : 1;
    const ssize_t n = read(opened.fd.get(), dst, want);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw PrivateFileError("cannot read " + file.named + ": " + Errno(errno));
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
    if (got > size) break;
  }
  if (got != size) {  // changed size while being read
    throw PrivateFileError(file.named + " changed while it was read (" + std::to_string(got) +
                           " bytes). Fix: retry once the file is written");
  }
}

void PreparePrivateDir(const PrivateFileNaming& file) {
  MakeParentDirs(file);
  const std::string dir = DirOf(file.path);
  struct stat st {};
  if (stat(dir.c_str(), &st) == 0) CheckPrivateDir(dir, st, file);
}

std::string WriteTempPrivateFile(const PrivateFileNaming& file, const uint8_t* bytes,
                                 std::size_t size) {
  const std::string dir = DirOf(file.path);
  std::string tmp = dir + "/.snapthread.XXXXXX";
  const UniqueFd fd(mkstemp(tmp.data()));
  if (fd.get() < 0) {
    throw PrivateFileError("cannot create a file for the " + file.named + " in " + dir + ": " +
                           Errno(errno));
  }
  auto fail = [&](const std::string& what) {
    const int err = errno;
    unlink(tmp.c_str());
    throw PrivateFileError("cannot write the " + file.named + " (" + what + "): " + Errno(err));
  };
  if (fchmod(fd.get(), 0600) != 0) fail("chmod");
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = write(fd.get(), bytes + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("write");
    done += static_cast<std::size_t>(n);
  }
  if (fsync(fd.get()) != 0) fail("fsync");
  return tmp;
}

void SyncDirOf(const std::string& file) {
  const std::string dir = DirOf(file);
  const UniqueFd fd(open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (fd.get() >= 0) fsync(fd.get());
}

bool WritePrivateFile(const PrivateFileNaming& file, const uint8_t* bytes, std::size_t size,
                      bool overwrite) {
  PreparePrivateDir(file);
  const std::string tmp = WriteTempPrivateFile(file, bytes, size);
  // link() fails when the name exists, so a file is never replaced by accident.
  const int done = overwrite ? rename(tmp.c_str(), file.path.c_str())
                             : link(tmp.c_str(), file.path.c_str());
  const int err = errno;
  if (!overwrite || done != 0) unlink(tmp.c_str());
  if (done != 0) {
    // A directory or a device in the file's place is nothing to keep: say what it is.
    struct stat st {};
    if (lstat(file.path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) throw NotAFile(file, st.st_mode);
    if (err == EEXIST) return false;
    throw PrivateFileError("cannot write " + file.named + ": " + Errno(err));
  }
  SyncDirOf(file.path);
  return true;
}

}  // namespace snapthread::auth
