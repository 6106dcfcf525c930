// Records the messages of the channels matching a regex into an LCM log file, in the format
// of LCM's lcm-logger (lcm-logplayer, lcm-spy and snapthread-report read it).
//
// Why not lcm-logger: liblcm's udpm reader thread drains the socket at once, but hands each
// message to the subscription's queue, and when that queue is full it drops the message.
// lcm-logger keeps LCM's default of 30 messages, which is 15 ms of a session (~2,100
// messages/s); on a loaded machine its handler thread is off the CPU longer than that, and
// the reader thread drops the burst that arrives meanwhile (measured: 200-550 messages lost
// per minute with 4 viewers at load 19 on 2 cores, none of them in the kernel: the socket's
// drop counter stayed 0, also with recv_buf_size=4 MiB). This logger gives its subscription
// a queue of kQueueMessages (a minute of traffic) and writes from the handler thread, so a
// stall only delays the writing.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <lcm/lcm-cpp.hpp>

namespace snapthread::logger {

struct LoggerOptions {
  std::string path;              // the log file
  std::string channel = ".*";    // channel regex (lcm_subscribe's)
  std::string lcm_url;           // resolved already (flag, environment, default)
  bool force = false;            // overwrite an existing file
  double duration_s = 0.0;       // stop after this long (0: at SIGINT / SIGTERM only)
  int flush_interval_ms = 100;   // flush the file at least this often (as lcm-logger)
};

class SessionLogger {
 public:
  // Messages LCM may hold for the handler thread before it drops: ~60 s of a session.
  static constexpr int kQueueMessages = 1 << 17;

  // Opens the file and subscribes; throws std::runtime_error with a message naming the file
  // or URL when either fails (an existing file without options.force, too).
  explicit SessionLogger(const LoggerOptions& options);
  ~SessionLogger();
  SessionLogger(const SessionLogger&) = delete;
  SessionLogger& operator=(const SessionLogger&) = delete;

  // Logs until options.duration_s has passed or `stop_fd` (a signalfd, or -1) is readable.
  // Returns false when LCM fails.
  bool Run(int stop_fd);
  int64_t messages() const { return messages_; }
  int64_t bytes() const { return bytes_; }
  int64_t write_errors() const { return write_errors_; }

 private:
  void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel);

  LoggerOptions options_;
  lcm::LCM lcm_;
  std::unique_ptr<lcm::LogFile> log_;
  lcm::Subscription* subscription_ = nullptr;
  int64_t messages_ = 0;
  int64_t bytes_ = 0;
  int64_t write_errors_ = 0;
};

}  // namespace snapthread::logger
