#include "checkpoint.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "auth/file_mac.h"

namespace snapthread::server {
namespace {

constexpr char kMagic[8] = {'S', 'N', 'A', 'P', 'C', 'K', 'P', 'T'};
constexpr const char* kMacDomain = "checkpoint";
// Mode of the file and of a state dir the server makes: the scene and state are the
// operator's, not the world's.
constexpr mode_t kFileMode = 0600;
constexpr mode_t kDirMode = 0700;

// ---------------------------------------------------------------- encoding

void PutU32(std::string* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void PutU64(std::string* out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void PutI64(std::string* out, int64_t v) { PutU64(out, static_cast<uint64_t>(v)); }
void PutString(std::string* out, const std::string& s) {
  PutU32(out, static_cast<uint32_t>(s.size()));
  out->append(s);
}
void PutVec(std::string* out, const Vec& v) {
  PutU32(out, static_cast<uint32_t>(v.size()));
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    uint64_t bits = 0;
    const double d = v[i];
    std::memcpy(&bits, &d, sizeof(bits));
    PutU64(out, bits);
  }
}

// Reads the payload front to back; every read checks the bytes left first.
class Reader {
 public:
  Reader(const char* data, size_t size) : p_(reinterpret_cast<const uint8_t*>(data)), left_(size) {}

  bool U32(uint32_t* v) {
    if (left_ < 4) return false;
    *v = 0;
    for (int i = 0; i < 4; ++i) *v |= static_cast<uint32_t>(p_[i]) << (8 * i);
    Advance(4);
    return true;
  }
  bool U64(uint64_t* v) {
    if (left_ < 8) return false;
    *v = 0;
    for (int i = 0; i < 8; ++i) *v |= static_cast<uint64_t>(p_[i]) << (8 * i);
    Advance(8);
    return true;
  }
  bool I64(int64_t* v) {
    uint64_t u = 0;
    if (!U64(&u)) return false;
    *v = static_cast<int64_t>(u);
    return true;
  }
  bool String(std::string* s) {
    uint32_t n = 0;
    if (!U32(&n) || n > left_) return false;
    s->assign(reinterpret_cast<const char*>(p_), n);
    Advance(n);
    return true;
  }
  bool Vector(Vec* v) {
    uint32_t n = 0;
    if (!U32(&n) || n > left_ / 8) return false;
    v->resize(n);
    for (uint32_t i = 0; i < n; ++i) {
      uint64_t bits = 0;
      U64(&bits);
      double d = 0.0;
      std::memcpy(&d, &bits, sizeof(d));
      (*v)[i] = d;
    }
    return true;
  }
  size_t left() const { return left_; }

 private:
  void Advance(size_t n) {
    p_ += n;
    left_ -= n;
  }
  const uint8_t* p_;
  size_t left_;
};

bool Refuse(std::string* reason, const std::string& why) {
  if (reason != nullptr) *reason = why;
  return false;
}

// The first non-finite entry of v, as "name[i] = value", or "".
std::string NonFinite(const char* name, const Vec& v) {
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      return std::string(name) + "[" + std::to_string(i) + "] = " + std::to_string(v[i]);
    }
  }
  return "";
}

// ---------------------------------------------------------------- files

std::string ErrnoText(int err) { return std::strerror(err); }

std::string DirOf(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

// Owns one descriptor.
class FileHandle {
 public:
  explicit FileHandle(int fd) : fd_(fd) {}
  FileHandle(const FileHandle&) = delete;
  FileHandle& operator=(const FileHandle&) = delete;
  ~FileHandle() {
    if (fd_ >= 0) ::close(fd_);
  }
  int fd() const { return fd_; }
  // Closes now and reports close's error (a deferred write error shows up here).
  int Close() {
    const int r = ::close(fd_);
    fd_ = -1;
    return r;
  }

 private:
  int fd_;
};

[[noreturn]] void Throw(const std::string& what, const std::string& path, int err) {
  throw CheckpointIoError("checkpoint " + path + ": " + what + " failed: " + ErrnoText(err));
}

}  // namespace

std::string EncodeCheckpoint(const Checkpoint& c, const auth::SessionKey& key) {
  std::string payload;
  PutI64(&payload, c.utime);
  PutI64(&payload, c.epoch);
  PutI64(&payload, c.seq);
  PutString(&payload, c.scene_name);
  PutString(&payload, c.scene_file);
  PutString(&payload, c.scene_text);
  PutString(&payload, c.method);
  PutVec(&payload, c.u);
  PutVec(&payload, c.x);

  std::string out(kMagic, sizeof(kMagic));
  PutU32(&out, kCheckpointVersion);
  PutU32(&out, static_cast<uint32_t>(payload.size()));
  out += payload;
  uint8_t checksum[auth::kFileChecksumBytes];
  auth::FileChecksum(out.data(), out.size(), checksum);
  out.append(reinterpret_cast<const char*>(checksum), sizeof(checksum));
  uint8_t tag[auth::kFileMacBytes];
  auth::FileMac(kMacDomain, out.data(), out.size(), key, tag);
  out.append(reinterpret_cast<const char*>(tag), sizeof(tag));
  return out;
}

bool DecodeCheckpoint(const std::string& bytes, const auth::SessionKey& key, Checkpoint* out,
                      std::string* reason) {
  if (bytes.size() < kCheckpointHeaderBytes) {
    return Refuse(reason, "truncated: " + std::to_string(bytes.size()) +
                              " bytes, shorter than the " +
                              std::to_string(kCheckpointHeaderBytes) + "-byte header");
  }
  if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    return Refuse(reason, "bad magic (not a snapthread checkpoint)");
  }
  Reader header(bytes.data() + sizeof(kMagic), kCheckpointHeaderBytes - sizeof(kMagic));
  uint32_t version = 0, payload_bytes = 0;
  header.U32(&version);
  header.U32(&payload_bytes);
  if (version != kCheckpointVersion) {
    return Refuse(reason, "unsupported version " + std::to_string(version) + " (this server reads " +
                              std::to_string(kCheckpointVersion) + ")");
  }
  const size_t expected =
      kCheckpointHeaderBytes + static_cast<size_t>(payload_bytes) + kCheckpointTrailerBytes;
  if (bytes.size() != expected) {
    return Refuse(reason, std::string(bytes.size() < expected ? "truncated" : "wrong length") +
                              ": " + std::to_string(bytes.size()) + " bytes, the header says " +
                              std::to_string(expected));
  }
  const size_t body = kCheckpointHeaderBytes + payload_bytes;
  uint8_t checksum[auth::kFileChecksumBytes];
  auth::FileChecksum(bytes.data(), body, checksum);
  if (std::memcmp(checksum, bytes.data() + body, sizeof(checksum)) != 0) {
    return Refuse(reason, "checksum mismatch (the file is damaged)");
  }
  const auto* tag = reinterpret_cast<const uint8_t*>(bytes.data() + body + sizeof(checksum));
  if (!auth::VerifyFileMac(kMacDomain, bytes.data(), body + sizeof(checksum), key, tag)) {
    return Refuse(reason, "not written with this session key (bad MAC, key id " + key.Id() + ")");
  }
  Checkpoint c;
  Reader r(bytes.data() + kCheckpointHeaderBytes, payload_bytes);
  const bool ok = r.I64(&c.utime) && r.I64(&c.epoch) && r.I64(&c.seq) && r.String(&c.scene_name) &&
                  r.String(&c.scene_file) && r.String(&c.scene_text) && r.String(&c.method) &&
                  r.Vector(&c.u) && r.Vector(&c.x);
  if (!ok) return Refuse(reason, "malformed payload (a field runs past its end)");
  if (r.left() != 0) {
    return Refuse(reason, "malformed payload (" + std::to_string(r.left()) + " bytes after the state)");
  }
  for (const auto& [name, v] : {std::pair<const char*, const Vec*>{"grasp u", &c.u}, {"state x", &c.x}}) {
    const std::string bad = NonFinite(name, *v);
    if (!bad.empty()) return Refuse(reason, "non-finite value in the " + bad);
  }
  if (out != nullptr) *out = std::move(c);
  return true;
}

std::string CheckpointPath(const std::string& state_dir, const std::string& session) {
  return state_dir + "/" + session + ".checkpoint";
}

void PrepareStateDir(const std::string& dir) {
  if (::mkdir(dir.c_str(), kDirMode) != 0 && errno != EEXIST) {
    throw CheckpointIoError("--state-dir: cannot create " + dir + ": " + ErrnoText(errno));
  }
  struct stat info {};
  if (::stat(dir.c_str(), &info) != 0) {
    throw CheckpointIoError("--state-dir: " + dir + ": " + ErrnoText(errno));
  }
  if (!S_ISDIR(info.st_mode)) throw CheckpointIoError("--state-dir: " + dir + " is not a directory");
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    throw CheckpointIoError("--state-dir: " + dir + " is not writable: " + ErrnoText(errno));
  }
}

void WriteTempFile(const std::string& path, const std::string& bytes) {
  const std::string tmp = path + ".tmp";
  FileHandle file(::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, kFileMode));
  if (file.fd() < 0) Throw("open", tmp, errno);
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(file.fd(), bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) Throw("write", tmp, n < 0 ? errno : EIO);
    done += static_cast<size_t>(n);
  }
  if (::fsync(file.fd()) != 0) Throw("fsync", tmp, errno);
  if (file.Close() != 0) Throw("close", tmp, errno);
}

void CommitTempFile(const std::string& path) {
  const std::string tmp = path + ".tmp";
  if (::rename(tmp.c_str(), path.c_str()) != 0) Throw("rename", tmp, errno);
  // The rename is durable only once the directory entry is.
  const std::string dir = DirOf(path);
  FileHandle d(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (d.fd() < 0) Throw("open of the directory", dir, errno);
  if (::fsync(d.fd()) != 0) Throw("fsync of the directory", dir, errno);
}

void WriteFileAtomically(const std::string& path, const std::string& bytes) {
  WriteTempFile(path, bytes);
  CommitTempFile(path);
}

ReadStatus ReadCheckpointFile(const std::string& path, std::string* bytes, std::string* reason) {
  FileHandle file(::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC));
  if (file.fd() < 0) {
    if (errno == ENOENT) return ReadStatus::kMissing;
    *reason = errno == ELOOP ? "a symbolic link (refused)" : "cannot open: " + ErrnoText(errno);
    return ReadStatus::kRefused;
  }
  struct stat info {};
  if (::fstat(file.fd(), &info) != 0) {
    *reason = "cannot stat: " + ErrnoText(errno);
    return ReadStatus::kRefused;
  }
  if (!S_ISREG(info.st_mode)) {
    *reason = "not a regular file";
    return ReadStatus::kRefused;
  }
  if (static_cast<uint64_t>(info.st_size) > kMaxCheckpointBytes) {
    *reason = "too large: " + std::to_string(info.st_size) + " bytes (at most " +
              std::to_string(kMaxCheckpointBytes) + ")";
    return ReadStatus::kRefused;
  }
  bytes->clear();
  char buf[65536];
  while (bytes->size() <= kMaxCheckpointBytes) {
    const ssize_t n = ::read(file.fd(), buf, sizeof(buf));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      *reason = "read failed: " + ErrnoText(errno);
      return ReadStatus::kRefused;
    }
    if (n == 0) return ReadStatus::kOk;
    bytes->append(buf, static_cast<size_t>(n));
  }
  *reason = "too large (grew while read)";
  return ReadStatus::kRefused;
}

}  // namespace snapthread::server
