#include "log_file_writer.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace snapthread::logger {
namespace {

constexpr uint32_t kSyncWord = 0xEDA1DA01;

void PutBigEndian(uint64_t v, int bytes, unsigned char* out) {
  for (int i = 0; i < bytes; ++i) out[i] = static_cast<unsigned char>(v >> (8 * (bytes - 1 - i)));
}

std::string Errno(const std::string& what) { return what + ": " + std::strerror(errno); }

}  // namespace

LogFileWriter::LogFileWriter(const LogFileOptions& options) : options_(options) {
  if (options_.max_bytes < 0) throw std::runtime_error("--max-bytes must not be negative");
  if (options_.rotate < 0) throw std::runtime_error("--rotate must not be negative");
  OpenNext();
}

LogFileWriter::~LogFileWriter() { Close(); }

void LogFileWriter::Close() {
  if (file_ != nullptr) std::fclose(file_);
  file_ = nullptr;
}

std::string LogFileWriter::NextPath() {
  if (options_.rotate > 0) return options_.path + ".0";
  if (files_started_ == 0) return options_.path;
  return options_.path + "." + std::to_string(files_started_);
}

void LogFileWriter::OpenNext() {
  Close();
  if (options_.rotate > 0) {
    // lcm-logger --rotate: LOG.(K-1) goes, every other file moves up by one.
    const std::string base = options_.path + ".";
    if (unlink((base + std::to_string(options_.rotate - 1)).c_str()) != 0 && errno != ENOENT) {
      throw std::runtime_error(Errno("cannot remove " + base + std::to_string(options_.rotate - 1)));
    }
    for (int k = options_.rotate - 2; k >= 0; --k) {
      const std::string from = base + std::to_string(k), to = base + std::to_string(k + 1);
      if (rename(from.c_str(), to.c_str()) != 0 && errno != ENOENT) {
        throw std::runtime_error(Errno("cannot rename " + from + " to " + to));
      }
    }
  }
  const std::string path = NextPath();
  const bool take_over = options_.force || options_.rotate > 0;
  // O_NONBLOCK: opening a FIFO for writing would otherwise wait for a reader (ENXIO instead);
  // it is cleared once the file is known to be regular.
  const int flags =
      O_WRONLY | O_CREAT | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK | (take_over ? O_TRUNC : O_EXCL);
  const int fd = open(path.c_str(), flags, 0600);
  if (fd < 0) {
    if (errno == ENXIO) {
      throw std::runtime_error(path + " is not a regular file (a FIFO or device): the log must be a file");
    }
    if (errno == EEXIST) {
      throw std::runtime_error("refusing to overwrite existing file " + path + " (--force overwrites it)");
    }
    if (errno == ELOOP) throw std::runtime_error(path + " is a symbolic link: the log must be a file");
    throw std::runtime_error(Errno("cannot write the log file " + path));
  }
  struct stat st {};
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    close(fd);
    throw std::runtime_error(path + " is not a regular file (a FIFO or device): the log must be a file");
  }
  if (fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK) != 0) {
    close(fd);
    throw std::runtime_error(Errno("cannot write the log file " + path));
  }
  // A file taken over with --force keeps its inode and would keep its mode: make it private.
  if (fchmod(fd, 0600) != 0) {
    close(fd);
    throw std::runtime_error(Errno("cannot make " + path + " private (chmod 600)"));
  }
  file_ = fdopen(fd, "wb");
  if (file_ == nullptr) {
    close(fd);
    throw std::runtime_error(Errno("cannot write the log file " + path));
  }
  current_path_ = path;
  file_bytes_ = 0;
  event_number_ = 0;
  files_started_++;
}

LogFileWriter::Result LogFileWriter::Write(int64_t timestamp_us, const std::string& channel,
                                           const void* data, int32_t size) {
  if (file_ == nullptr) return Result::kFailed;
  const int64_t bytes = EventBytes(channel.size(), size);
  if (options_.max_bytes > 0) {
    if (bytes > options_.max_bytes) return Result::kTooLarge;
    if (file_bytes_ > 0 && file_bytes_ + bytes > options_.max_bytes) {
      try {
        OpenNext();
      } catch (const std::exception& e) {
        error_ = e.what();
        Close();
        return Result::kFailed;
      }
    }
  }
  unsigned char header[28];
  PutBigEndian(kSyncWord, 4, header);
  PutBigEndian(uint64_t(event_number_), 8, header + 4);
  PutBigEndian(uint64_t(timestamp_us), 8, header + 12);
  PutBigEndian(uint32_t(channel.size()), 4, header + 20);
  PutBigEndian(uint32_t(size), 4, header + 24);
  if (std::fwrite(header, 1, sizeof header, file_) != sizeof header ||
      std::fwrite(channel.data(), 1, channel.size(), file_) != channel.size() ||
      std::fwrite(data, 1, size_t(size), file_) != size_t(size)) {
    error_ = Errno("cannot write " + current_path_);
    return Result::kFailed;
  }
  file_bytes_ += bytes;
  event_number_++;
  return Result::kWritten;
}

void LogFileWriter::Flush() {
  if (file_ != nullptr && std::fflush(file_) != 0 && error_.empty()) {
    error_ = Errno("cannot write " + current_path_);
  }
}

}  // namespace snapthread::logger
