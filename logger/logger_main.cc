// snapthread-logger: records a session into an LCM log file without losing messages under
// load (session_logger.h); the command line follows lcm-logger's.
// Exit codes (common/app/exit_codes.h, docs/cli.md): 0 after SIGINT / SIGTERM or
// --duration-s with every message written; 1 for an LCM or file failure, or messages
// lost; 2 for bad arguments.
#include <cstdio>
#include <ctime>
#include <exception>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "app/command_line.h"
#include "app/common_flags.h"
#include "app/exit_codes.h"
#include "app/stop_signals.h"
#include "session_logger.h"

namespace {

namespace app = snapthread::app;
namespace logger = snapthread::logger;

constexpr const char* kProgram = "snapthread-logger";
constexpr const char* kDescription =
    "snapthread-logger: records the LCM messages of the channels matching CHAN into FILE "
    "(lcm-logger's log format, files of mode 0600), queueing up to --max-queue-bytes of "
    "traffic so that a busy machine delays the writing instead of dropping messages. "
    "--max-bytes / --rotate split and rotate files like lcm-logger's --split-mb / --rotate. "
    "Ends at SIGINT / SIGTERM or after --duration-s.";
// snapthread-logger has always exited 1 for every failure (app/exit_codes.h).
constexpr int kExitBadArguments = app::kExitUsage;

struct LoggerFlags {
  logger::LoggerOptions options;
  app::CommonFlags common;  // -l,--lcm-url only
  bool quiet = false;
  bool use_strftime = false;
};

void AddLoggerFlags(CLI::App* cli, LoggerFlags* f) {
  logger::LoggerOptions& o = f->options;
  cli->add_option("file", o.path, "the log file")->required();
  cli->add_option("-c,--channel", o.channel, "channel regex")->capture_default_str();
  app::CommonFlagSet common;  // lcm-logger's -l; a recorder needs no session or key
  common.session = false;
  common.key = false;
  common.lcm_url_names = "-l,--lcm-url";
  app::AddCommonFlags(cli, &f->common, common);
  cli->add_flag("-f,--force", o.force, "overwrite an existing file");
  cli->add_flag("-s,--strftime", f->use_strftime, "format FILE with strftime (local time), as lcm-logger -s");
  cli->add_flag("-q,--quiet", f->quiet, "no summary at the end");
  cli->add_option("--duration-s", o.duration_s, "stop after this many seconds (0 = at a signal)")
      ->capture_default_str()->check(CLI::NonNegativeNumber)->check(app::FiniteNumber());
  cli->add_option("--flush-interval", o.flush_interval_ms, "flush the file every MS milliseconds")
      ->capture_default_str()->check(CLI::Range(1, 10000));
  cli->add_option("--max-bytes", o.max_bytes,
                  "start a new file before one would pass N bytes: FILE, FILE.1, FILE.2, ... "
                  "(lcm-logger --split-mb, in bytes; 0 = one file)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  cli->add_option("--rotate", o.rotate,
                  "write FILE.0 and keep K files: a new file renames FILE.0 -> FILE.1 -> ... and "
                  "deletes FILE.K-1 (lcm-logger --rotate; existing files are rotated, not refused)")
      ->check(CLI::Range(1, 1000));
  cli->add_option("--max-queue-bytes", o.max_queue_bytes,
                  "received but unwritten messages held at most; beyond, messages are dropped and "
                  "counted (lcm-logger --max-unwritten-mb, in bytes)")
      ->capture_default_str()->check(CLI::PositiveNumber);
}

// FILE through strftime (local time), as lcm-logger -s; false when it formats to nothing.
bool FormatPath(std::string* path) {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char name[4096];
  if (std::strftime(name, sizeof name, path->c_str(), &local) == 0) return false;
  *path = name;
  return true;
}

// The counts at the end (always when something was lost or failed), and what failed.
void PrintOutcome(const logger::SessionLogger& logger, const std::string& lcm_url, bool ok, bool quiet) {
  const logger::QueueCounts q = logger.queue_counts();
  const bool lost = logger.write_errors() > 0 || q.dropped_messages > 0 || logger.too_large() > 0;
  if (!quiet || !ok || lost) {
    std::printf("snapthread-logger: %lld messages (%lld bytes) in %d file%s (last %s), %lld "
                "dropped (queue full, %lld bytes; peak queue %lld bytes), %lld larger than "
                "--max-bytes, %lld write errors\n",
                static_cast<long long>(logger.messages()), static_cast<long long>(logger.bytes()),
                logger.files(), logger.files() == 1 ? "" : "s", logger.current_path().c_str(),
                static_cast<long long>(q.dropped_messages), static_cast<long long>(q.dropped_bytes),
                static_cast<long long>(q.peak_bytes), static_cast<long long>(logger.too_large()),
                static_cast<long long>(logger.write_errors()));
  }
  if (!logger.file_error().empty()) {
    std::fprintf(stderr, "snapthread-logger: %s\n", logger.file_error().c_str());
  }
  if (!ok && logger.file_error().empty()) {
    std::fprintf(stderr, "snapthread-logger: LCM handle failed on %s\n", lcm_url.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  LoggerFlags f;
  CLI::App cli{kDescription};
  AddLoggerFlags(&cli, &f);
  if (auto code = app::ParseCommandLine(cli, argc, argv, kExitBadArguments)) return *code;
  logger::LoggerOptions& o = f.options;
  if (f.use_strftime && !FormatPath(&o.path)) {
    return app::Fail(kProgram, kExitBadArguments, "--strftime: '" + o.path + "' formats to nothing");
  }
  // A receiver: a kernel buffer that rides out seconds off the CPU (lcm_url.h).
  o.lcm_url = app::LcmUrl(f.common);
  // The stop signals arrive on a signalfd that the loop polls next to LCM's; blocked
  // before LCM starts its reader thread, so every thread inherits the mask.
  app::StopSignals stop;
  const int stop_fd = stop.OpenFd();
  std::optional<logger::SessionLogger> logger;
  try {
    logger.emplace(o);
  } catch (const std::exception& e) {
    return app::Fail(kProgram, app::kExitFailure, e.what());
  }
  const bool ok = logger->Run(stop_fd);
  PrintOutcome(*logger, o.lcm_url, ok, f.quiet);
  return ok && logger->write_errors() == 0 ? app::kExitOk : app::kExitFailure;
}
