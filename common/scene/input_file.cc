#include "scene/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace snapthread {
namespace {

std::string Bytes(std::size_t n) {
  if (n >= (1u << 20) && n % (1u << 20) == 0) return std::to_string(n >> 20) + " MiB";
  return std::to_string(n) + " bytes";
}

}  // namespace

const char* FileKindName(unsigned int st_mode) {
  const mode_t mode = static_cast<mode_t>(st_mode);
  if (S_ISREG(mode)) return "a regular file";
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string ReadInputFile(const std::string& path, std::size_t max_bytes, const std::string& what) {
  if (path.empty()) throw InputFileError("empty file name (expected a " + what + ")");
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    throw InputFileError(path + ": cannot open " + what + " (" + std::strerror(errno) + ")");
  }
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat info {};
  if (::fstat(fd, &info) != 0) {
    throw InputFileError(path + ": cannot stat " + what + " (" + std::strerror(errno) + ")");
  }
  if (!S_ISREG(info.st_mode)) {
    throw InputFileError(path + ": is " + FileKindName(info.st_mode) + ", not a regular file (expected a " +
                         what + ")");
  }
  if (static_cast<unsigned long long>(info.st_size) > max_bytes) {
    throw InputFileError(path + ": " + std::to_string(info.st_size) + " bytes, over the " + Bytes(max_bytes) +
                         " limit for a " + what);
  }
  std::string text;
  char buf[65536];
  while (true) {
    const ssize_t n = ::read(fd, buf, sizeof(buf));
    if (n < 0) {
      if (errno == EINTR) continue;
      throw InputFileError(path + ": cannot read " + what + " (" + std::strerror(errno) + ")");
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
    // The file grew after the fstat: still bounded.
    if (text.size() > max_bytes) {
      throw InputFileError(path + ": grew over the " + Bytes(max_bytes) + " limit for a " + what +
                           " while being read");
    }
  }
  return text;
}

}  // namespace snapthread
