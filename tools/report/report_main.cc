// snapthread-report LOGFILE [--out DIR] [--session NAME]: review of a logged session.
// Exit 0 when a report was written (with a warning on stderr when the log was only partly
// readable), 2 when nothing could be read or the log is larger than --max-log-bytes, 1 on
// usage errors. Every byte of the log is hostile: channel names and strings are shown
// escaped, only a valid session name is used, and gnuplot runs without a shell.
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>

#include <CLI/CLI.hpp>

#include "gnuplot_plots.h"
#include "messages/channels.h"
#include "log_reader.h"
#include "session_review.h"

int main(int argc, char** argv) {
  using namespace snapthread::report;
  std::string log_path, out_dir, session;
  bool no_plots = false;
  // A review holds every force model in memory: 2 GiB of log is hours of a session.
  int64_t max_log_bytes = int64_t{2} << 30;
  CLI::App app{"snapthread-report: turns an LCM log of a snapthread session into CSV files, "
               "gnuplot PNG plots and summary.txt"};
  app.add_option("LOGFILE", log_path, "LCM log written by lcm-logger")->required();
  app.add_option("--out", out_dir, "output directory (default: <LOGFILE>.report)");
  app.add_option("--session", session, "session name (default: the busiest one in the log)");
  app.add_flag("--no-plots", no_plots, "write CSV and summary only (no gnuplot)");
  app.add_option("--max-log-bytes", max_log_bytes,
                 "refuse a log larger than this (split long sessions: snapthread-logger --max-bytes)")
      ->capture_default_str()->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  if (!session.empty() && !snapthread::messages::IsValidSessionName(session)) {
    std::fprintf(stderr, "snapthread-report: bad --session %s: expected 1 to %zu characters of "
                         "[A-Za-z0-9_]\n",
                 snapthread::messages::EscapeForDisplay(session).c_str(),
                 snapthread::messages::kMaxSessionNameLength);
    return 1;
  }
  {
    std::error_code size_error;
    const auto size = std::filesystem::file_size(log_path, size_error);
    if (!size_error && size > uint64_t(max_log_bytes)) {
      std::fprintf(stderr,
                   "snapthread-report: %s is %llu bytes, larger than the limit of %lld bytes "
                   "(--max-log-bytes): refused. Split the session (snapthread-logger "
                   "--max-bytes) or raise --max-log-bytes\n",
                   log_path.c_str(), static_cast<unsigned long long>(size),
                   static_cast<long long>(max_log_bytes));
      return 2;
    }
  }
  if (out_dir.empty()) out_dir = log_path + ".report";

  std::string error;
  if (session.empty()) {
    std::map<std::string, int64_t> counts;
    LogReadStats scan;
    if (!ReadLog(log_path, [&](const lcm::LogEvent& e) { counts[e.channel]++; }, &scan, &error)) {
      std::fprintf(stderr, "snapthread-report: %s\n", error.c_str());
      return 2;
    }
    session = InferSession(counts);
    if (session.empty() && !counts.empty()) {
      std::fprintf(stderr, "snapthread-report: warning: no snapthread channels in %s; counting "
                           "channels only\n", log_path.c_str());
    }
  }
  SessionReview review(session);
  LogReadStats read;
  if (!ReadLog(log_path, [&](const lcm::LogEvent& e) { review.Add(e); }, &read, &error)) {
    std::fprintf(stderr, "snapthread-report: %s\n", error.c_str());
    return 2;
  }
  if (read.events == 0) {
    std::fprintf(stderr, "snapthread-report: no readable events in %s (%lld bytes)%s%s\n",
                 log_path.c_str(), static_cast<long long>(read.file_bytes),
                 read.warnings.empty() ? "" : ": ",
                 read.warnings.empty() ? "" : read.warnings.front().c_str());
    return 2;
  }
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    std::fprintf(stderr, "snapthread-report: cannot create %s: %s\n", out_dir.c_str(),
                 ec.message().c_str());
    return 1;
  }
  review.WriteCsv(out_dir);
  PlotOutcome plots;
  if (!no_plots) plots = MakePlots(out_dir, review);
  const std::string summary = review.Summary(log_path, read, plots.written, plots.notes);
  std::ofstream(out_dir + "/summary.txt") << summary;
  std::printf("%s\nsnapthread-report: wrote %s/summary.txt, CSV files and %zu plots\n",
              summary.c_str(), out_dir.c_str(), plots.written.size());
  if (read.Partial()) {
    std::fprintf(stderr,
                 "snapthread-report: WARNING: partial report: the log is damaged or truncated "
                 "(%lld of %lld bytes unreadable); the report covers the %lld intact events\n",
                 static_cast<long long>(read.skipped_bytes),
                 static_cast<long long>(read.file_bytes), static_cast<long long>(read.events));
  }
  return 0;
}
