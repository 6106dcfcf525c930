// snapthread-logger: records a session into an LCM log file without losing messages under
// load (session_logger.h); the command line follows lcm-logger's.
#include <signal.h>
#include <sys/signalfd.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <exception>
#include <optional>

#include <CLI/CLI.hpp>

#include "messages/lcm_url.h"
#include "session_logger.h"

int main(int argc, char** argv) {
  snapthread::logger::LoggerOptions o;
  bool quiet = false;
  CLI::App app{
      "snapthread-logger: records the LCM messages of the channels matching CHAN into FILE "
      "(lcm-logger's log format, files of mode 0600), queueing up to --max-queue-bytes of "
      "traffic so that a busy machine delays the writing instead of dropping messages. "
      "--max-bytes / --rotate split and rotate files like lcm-logger's --split-mb / --rotate. "
      "Ends at SIGINT / SIGTERM or after --duration-s."};
  app.add_option("file", o.path, "the log file")->required();
  app.add_option("-c,--channel", o.channel, "channel regex")->capture_default_str();
  app.add_option("-l,--lcm-url", o.lcm_url,
                 "LCM URL (default: env LCM_DEFAULT_URL, else udpm://239.255.76.67:7667?ttl=0)");
  app.add_flag("-f,--force", o.force, "overwrite an existing file");
  bool use_strftime = false;
  app.add_flag("-s,--strftime", use_strftime, "format FILE with strftime (local time), as lcm-logger -s");
  app.add_flag("-q,--quiet", quiet, "no summary at the end");
  app.add_option("--duration-s", o.duration_s, "stop after this many seconds (0 = at a signal)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--flush-interval", o.flush_interval_ms, "flush the file every MS milliseconds")
      ->capture_default_str()->check(CLI::Range(1, 10000));
  app.add_option("--max-bytes", o.max_bytes,
                 "start a new file before one would pass N bytes: FILE, FILE.1, FILE.2, ... "
                 "(lcm-logger --split-mb, in bytes; 0 = one file)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--rotate", o.rotate,
                 "write FILE.0 and keep K files: a new file renames FILE.0 -> FILE.1 -> ... and "
                 "deletes FILE.K-1 (lcm-logger --rotate; existing files are rotated, not refused)")
      ->check(CLI::Range(1, 1000));
  app.add_option("--max-queue-bytes", o.max_queue_bytes,
                 "received but unwritten messages held at most; beyond, messages are dropped and "
                 "counted (lcm-logger --max-unwritten-mb, in bytes)")
      ->capture_default_str()->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  if (!std::isfinite(o.duration_s)) {  // CLI11's NonNegativeNumber lets "nan" through
    std::fprintf(stderr, "snapthread-logger: --duration-s: expected a finite number\n");
    return 1;
  }
  if (use_strftime) {
    const std::time_t now = std::time(nullptr);
    std::tm local{};
    localtime_r(&now, &local);
    char name[4096];
    if (std::strftime(name, sizeof name, o.path.c_str(), &local) == 0) {
      std::fprintf(stderr, "snapthread-logger: --strftime: '%s' formats to nothing\n", o.path.c_str());
      return 1;
    }
    o.path = name;
  }
  // A receiver: a kernel buffer that rides out seconds off the CPU (lcm_url.h).
  o.lcm_url = snapthread::messages::WithReceiveBuffer(snapthread::messages::ResolveLcmUrl(o.lcm_url));

  // SIGINT / SIGTERM arrive on a signalfd that the loop polls next to LCM's: blocked before
  // LCM starts its reader thread, so every thread inherits the mask.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  const int stop_fd = signalfd(-1, &stop_signals, SFD_CLOEXEC);

  std::optional<snapthread::logger::SessionLogger> logger;
  try {
    logger.emplace(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "snapthread-logger: %s\n", e.what());
    return 1;
  }
  const bool ok = logger->Run(stop_fd);
  const snapthread::logger::QueueCounts q = logger->queue_counts();
  const bool lost = logger->write_errors() > 0 || q.dropped_messages > 0 || logger->too_large() > 0;
  if (!quiet || !ok || lost) {
    std::printf("snapthread-logger: %lld messages (%lld bytes) in %d file%s (last %s), %lld "
                "dropped (queue full, %lld bytes; peak queue %lld bytes), %lld larger than "
                "--max-bytes, %lld write errors\n",
                static_cast<long long>(logger->messages()), static_cast<long long>(logger->bytes()),
                logger->files(), logger->files() == 1 ? "" : "s", logger->current_path().c_str(),
                static_cast<long long>(q.dropped_messages), static_cast<long long>(q.dropped_bytes),
                static_cast<long long>(q.peak_bytes), static_cast<long long>(logger->too_large()),
                static_cast<long long>(logger->write_errors()));
  }
  if (!logger->file_error().empty()) {
    std::fprintf(stderr, "snapthread-logger: %s\n", logger->file_error().c_str());
  }
  if (!ok && logger->file_error().empty()) {
    std::fprintf(stderr, "snapthread-logger: LCM handle failed on %s\n", o.lcm_url.c_str());
  }
  return ok && logger->write_errors() == 0 ? 0 : 1;
}
