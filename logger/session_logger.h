// Records the messages of the channels matching a regex into LCM log files, in the format
// of LCM's lcm-logger (lcm-logplayer, lcm-spy and snapthread-report read it).
//
// Why not lcm-logger: liblcm's udpm reader thread drains the socket at once, but hands each
// message to the subscription's queue, and when that queue is full it drops the message.
// lcm-logger keeps LCM's default of 30 messages, which is 15 ms of a session (~2,100
// messages/s); on a loaded machine its handler thread is off the CPU longer than that, and
// the reader thread drops the burst that arrives meanwhile (measured: 211-545 messages lost
// per minute with 4 viewers at load 13-19 on 2 cores, none of them in the kernel: the
// socket's drop counter stayed 0, also with recv_buf_size=4 MiB; docs/lab-setup.md).
//
// So this logger's handler thread only copies each message into its own queue, bounded in
// bytes (--max-queue-bytes, as lcm-logger's --max-unwritten-mb), and a writer thread puts
// the queue on disk: a stall of either delays the writing, and only a queue full for longer
// than the disk can catch up drops messages, counted and reported once per second. The
// writer takes the queue a batch at a time (one wake-up per batch). LCM's own subscription
// queue in front of the handler is bounded in messages only (kLcmQueueMessages): liblcm
// 1.3.1 has no byte limit, and what it drops there is not counted.
// Files are private (0600) and split / rotated like lcm-logger's (log_file_writer.h).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "log_file_writer.h"
#include "message_queue.h"

namespace snapthread::logger {

struct LoggerOptions {
  std::string path;              // the log file (LOG, or LOG.0 with rotate)
  std::string channel = ".*";    // channel regex (lcm_subscribe's)
  std::string lcm_url;           // resolved already (flag, environment, default)
  bool force = false;            // overwrite an existing file
  double duration_s = 0.0;       // stop after this long (0: at SIGINT / SIGTERM only)
  int flush_interval_ms = 100;   // flush the file at least this often (as lcm-logger)
  int64_t max_bytes = 0;         // split files at this size (0: one file)
  int rotate = 0;                // keep this many files, lcm-logger --rotate style
  int64_t max_queue_bytes = int64_t{256} << 20;  // unwritten messages held at most
};

class SessionLogger {
 public:
  // Messages LCM may hold for the handler thread before it drops (~60 s of a session). The
  // handler only copies into queue_, so LCM's queue fills only while the handler thread is
  // off the CPU; the disk's delays land in queue_, which is bounded in bytes.
  static constexpr int kLcmQueueMessages = 1 << 17;

  // Opens the file and subscribes; throws std::runtime_error with a message naming the file
  // or URL when either fails (an existing file without options.force, too).
  explicit SessionLogger(const LoggerOptions& options);
  ~SessionLogger();
  SessionLogger(const SessionLogger&) = delete;
  SessionLogger& operator=(const SessionLogger&) = delete;

  // Logs until options.duration_s has passed or `stop_fd` (a signalfd, or -1) is readable,
  // then writes out what is queued. Returns false when LCM or the log files fail.
  bool Run(int stop_fd);
  int64_t messages() const { return messages_; }
  int64_t bytes() const { return bytes_; }
  int64_t write_errors() const { return write_errors_; }
  int64_t too_large() const { return too_large_; }  // larger than max_bytes, not written
  QueueCounts queue_counts() const { return queue_.counts(); }
  int files() const { return writer_->files_started(); }
  const std::string& current_path() const { return writer_->current_path(); }
  const std::string& file_error() const { return writer_->error(); }

 private:
  void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void WriteLoop();

  LoggerOptions options_;
  lcm::LCM lcm_;
  std::unique_ptr<LogFileWriter> writer_;
  MessageQueue queue_;
  lcm::Subscription* subscription_ = nullptr;
  // Written by the writer thread, read after it is joined.
  int64_t messages_ = 0;
  int64_t bytes_ = 0;
  int64_t write_errors_ = 0;
  int64_t too_large_ = 0;
  std::atomic<bool> writer_failed_{false};  // the files cannot be written: stop
  std::atomic<bool> stop_writer_{false};    // the LCM loop has ended
};

}  // namespace snapthread::logger
