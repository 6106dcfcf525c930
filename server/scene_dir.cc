#include "scene_dir.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>

#include "scene/input_file.h"

namespace snapthread::server {
namespace {

// Closes a descriptor at scope exit.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

std::string RealPath(const std::string& path) {
  char buf[PATH_MAX];
  if (::realpath(path.c_str(), buf) == nullptr) return "";
  return buf;
}

}  // namespace

std::string DefaultSceneDir() { return SNAPTHREAD_SCENES_DIR; }

std::string SceneFileName(const std::string& name) {
  const std::string quoted = "LOAD_SCENE '" + name + "' refused: ";
  if (name.empty()) throw SceneNameError(quoted + "empty scene name");
  if (name.find('/') != std::string::npos || name.find('\\') != std::string::npos) {
    throw SceneNameError(quoted + "a path separator; scenes are loaded by name (e.g. curve2d_snap) "
                                  "from the scene directory");
  }
  if (name.find("..") != std::string::npos) throw SceneNameError(quoted + "'..' in the name");
  if (name[0] == '.') throw SceneNameError(quoted + "a name may not start with '.'");
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    if (!ok) throw SceneNameError(quoted + "characters other than [A-Za-z0-9_.-] in the name");
  }
  constexpr const char* kExt = ".yaml";
  if (name.size() > 5 && name.compare(name.size() - 5, 5, kExt) == 0) return name;
  return name + kExt;
}

std::string ReadSceneByName(const std::string& dir, const std::string& name, std::string* path) {
  const std::string file = SceneFileName(name);
  const std::string quoted = "LOAD_SCENE '" + name + "' refused: ";
  const std::string real_dir = RealPath(dir);
  if (real_dir.empty()) {
    throw SceneNameError(quoted + "the scene directory " + dir + " is not accessible (" +
                         std::strerror(errno) + ")");
  }
  const std::string full = real_dir + "/" + file;
  if (path != nullptr) *path = full;
  struct stat link_info {};
  if (::lstat(full.c_str(), &link_info) != 0) {
    throw SceneNameError(quoted + "no scene " + file + " in " + real_dir);
  }
  if (S_ISLNK(link_info.st_mode)) {
    const std::string target = RealPath(full);
    if (target.empty() || target.compare(0, real_dir.size() + 1, real_dir + "/") != 0) {
      throw SceneNameError(quoted + file + " is a symbolic link that resolves outside " + real_dir);
    }
    throw SceneNameError(quoted + file + " is a symbolic link (scenes must be regular files in " +
                         real_dir + ")");
  }
  Fd dir_fd{::open(real_dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC)};
  if (dir_fd.fd < 0) {
    throw SceneNameError(quoted + "cannot open the scene directory " + real_dir + " (" +
                         std::strerror(errno) + ")");
  }
  // The leaf name has no '/', so openat cannot leave the directory; O_NOFOLLOW refuses a
  // symlink swapped in after the lstat; O_NONBLOCK keeps a FIFO from blocking the open.
  Fd fd{::openat(dir_fd.fd, file.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC)};
  if (fd.fd < 0) {
    const int err = errno;
    if (err == ELOOP) throw SceneNameError(quoted + file + " is a symbolic link");
    throw SceneNameError(quoted + "cannot open " + full + " (" + std::strerror(err) + ")");
  }
  struct stat info {};
  if (::fstat(fd.fd, &info) != 0) {
    throw SceneNameError(quoted + "cannot stat " + full + " (" + std::strerror(errno) + ")");
  }
  if (!S_ISREG(info.st_mode)) {
    throw SceneNameError(quoted + full + " is " + FileKindName(info.st_mode) +
                         ", not a regular file");
  }
  if (static_cast<unsigned long long>(info.st_size) > kMaxSceneFileBytes) {
    throw SceneNameError(quoted + full + " is " + std::to_string(info.st_size) +
                         " bytes, over the 1 MiB limit for a scene file");
  }
  std::string text;
  char buf[65536];
  while (true) {
    const ssize_t n = ::read(fd.fd, buf, sizeof(buf));
    if (n < 0) {
      if (errno == EINTR) continue;
      throw SceneNameError(quoted + "cannot read " + full + " (" + std::strerror(errno) + ")");
    }
    if (n == 0) break;
    text.append(buf, static_cast<size_t>(n));
    // The file grew after the fstat: still bounded.
    if (text.size() > kMaxSceneFileBytes) {
      throw SceneNameError(quoted + full + " grew over the 1 MiB limit while being read");
    }
  }
  return text;
}

}  // namespace snapthread::server
