// Writes LCM log events (lcm-logger's file format: sync word, event number, time, channel
// and data lengths, channel, data; big-endian) into a series of private files.
//
// Files are created with mode 0600 (also an existing file taken over with --force), opened
// without following a symbolic link, and must be regular files. Splitting follows
// lcm-logger's --split-mb / --rotate, with the size in bytes:
//  * max_bytes > 0, rotate == 0: LOG, then LOG.1, LOG.2, ... (lcm-logger -i --split-mb);
//    each file holds at most max_bytes (an event never straddles two files).
//  * rotate = K > 0: lcm-logger --rotate K: the current file is always LOG.0; starting it
//    renames LOG.0 -> LOG.1 -> ... -> LOG.(K-1), and the file beyond is deleted, so at most
//    K files (K * max_bytes bytes) remain.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

namespace snapthread::logger {

struct LogFileOptions {
  std::string path;       // LOG
  bool force = false;     // take over existing files (rotate implies it, as in lcm-logger)
  int64_t max_bytes = 0;  // split at this size; 0: one file
  int rotate = 0;         // keep this many files, lcm-logger style; 0: number them up
};

class LogFileWriter {
 public:
  enum class Result { kWritten, kTooLarge, kFailed };

  // Opens the first file; throws std::runtime_error naming the file and the reason.
  explicit LogFileWriter(const LogFileOptions& options);
  ~LogFileWriter();
  LogFileWriter(const LogFileWriter&) = delete;
  LogFileWriter& operator=(const LogFileWriter&) = delete;

  // Appends one event, moving to the next file first when it would pass max_bytes.
  // kTooLarge: the event alone is larger than max_bytes (not written); kFailed: a write or
  // the next file failed (error() says why; later calls fail too).
  Result Write(int64_t timestamp_us, const std::string& channel, const void* data, int32_t size);
  void Flush();

  const std::string& current_path() const { return current_path_; }
  int files_started() const { return files_started_; }
  const std::string& error() const { return error_; }

  // The encoded size of one event in the file.
  static int64_t EventBytes(size_t channel_size, int64_t data_size) {
    return 28 + int64_t(channel_size) + data_size;
  }

 private:
  void OpenNext();  // throws std::runtime_error
  std::string NextPath();
  void Close();

  LogFileOptions options_;
  std::FILE* file_ = nullptr;
  std::string current_path_;
  int64_t file_bytes_ = 0;
  int64_t event_number_ = 0;  // per file, as lcm-logger numbers them
  int files_started_ = 0;
  std::string error_;
};

}  // namespace snapthread::logger
