// snapthread-report LOGFILE [--out DIR] [--session NAME]: review of a logged session.
// Exit 0 when a report was written (with a warning on stderr when the log was only partly
// readable), 2 when nothing could be read or the log is larger than --max-log-bytes, 1 on
// usage errors (app/exit_codes.h: the report keeps these). Every byte of the log is
// hostile: channel names and strings are shown escaped, only a valid session name is
// used, and gnuplot runs without a shell.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "app/command_line.h"
#include "app/common_flags.h"
#include "app/exit_codes.h"
#include "auth/key_file.h"
#include "auth/role.h"
#include "gnuplot_plots.h"
#include "log_reader.h"
#include "session_review.h"

namespace {

namespace app = snapthread::app;
using namespace snapthread::report;

constexpr const char* kProgram = "snapthread-report";
constexpr int kExitBadArguments = app::kExitUsage;
// Nothing of the log could be read, or it is too large: a failure outside the arguments.
constexpr int kExitUnreadable = app::kExitFailure;

struct ReportOptions {
  std::string log_path, out_dir;
  app::CommonFlags common;  // --session only; "" = the busiest session in the log
  bool no_plots = false;
  // A review holds every force model in memory: 2 GiB of log is hours of a session.
  int64_t max_log_bytes = int64_t{2} << 30;
};

void AddReportFlags(CLI::App* cli, ReportOptions* o) {
  cli->add_option("LOGFILE", o->log_path, "LCM log written by lcm-logger")->required();
  cli->add_option("--out", o->out_dir, "output directory (default: <LOGFILE>.report)");
  app::CommonFlagSet common;
  common.lcm_url = false;
  common.key_note = "; needed only for a sealed (--encrypt) log: an observer credential of the session";
  common.session_note = "; default: the busiest one in the log";
  o->common.session.clear();
  app::AddCommonFlags(cli, &o->common, common);
  cli->add_flag("--no-plots", o->no_plots, "write CSV and summary only (no gnuplot)");
  cli->add_option("--max-log-bytes", o->max_log_bytes,
                  "refuse a log larger than this (split long sessions: snapthread-logger --max-bytes)")
      ->capture_default_str()->check(CLI::PositiveNumber);
}

// A log larger than --max-log-bytes is refused before reading it.
std::optional<int> CheckLogSize(const ReportOptions& o) {
  std::error_code size_error;
  const auto size = std::filesystem::file_size(o.log_path, size_error);
  if (size_error || size <= uint64_t(o.max_log_bytes)) return std::nullopt;
  std::fprintf(stderr,
               "snapthread-report: %s is %llu bytes, larger than the limit of %lld bytes "
               "(--max-log-bytes): refused. Split the session (snapthread-logger "
               "--max-bytes) or raise --max-log-bytes\n",
               o.log_path.c_str(), static_cast<unsigned long long>(size), static_cast<long long>(o.max_log_bytes));
  return kExitUnreadable;
}

// Without --session: the busiest session of the log (a first pass counting channels).
std::optional<int> InferSessionFromLog(ReportOptions* o) {
  std::map<std::string, int64_t> counts;
  LogReadStats scan;
  std::string error;
  if (!ReadLog(o->log_path, [&](const lcm::LogEvent& e) { counts[e.channel]++; }, &scan, &error)) {
    return app::Fail(kProgram, kExitUnreadable, error);
  }
  o->common.session = InferSession(counts);
  if (o->common.session.empty() && !counts.empty()) {
    std::fprintf(stderr, "snapthread-report: warning: no snapthread channels in %s; counting "
                         "channels only\n", o->log_path.c_str());
  }
  return std::nullopt;
}

// Reads the log into `review`; nullopt when at least one event was read.
std::optional<int> ReadReview(const ReportOptions& o, SessionReview* review, LogReadStats* read) {
  std::string error;
  if (!ReadLog(o.log_path, [&](const lcm::LogEvent& e) { review->Add(e); }, read, &error)) {
    return app::Fail(kProgram, kExitUnreadable, error);
  }
  if (read->events > 0) return std::nullopt;
  std::fprintf(stderr, "snapthread-report: no readable events in %s (%lld bytes)%s%s\n", o.log_path.c_str(),
               static_cast<long long>(read->file_bytes), read->warnings.empty() ? "" : ": ",
               read->warnings.empty() ? "" : read->warnings.front().c_str());
  return kExitUnreadable;
}

// The CSV files, plots and summary.txt in --out; says where, and warns of a partial log.
int WriteReport(const ReportOptions& o, const SessionReview& review, const LogReadStats& read) {
  std::error_code ec;
  std::filesystem::create_directories(o.out_dir, ec);
  if (ec) return app::Fail(kProgram, app::kExitFailure, "cannot create " + o.out_dir + ": " + ec.message());
  review.WriteCsv(o.out_dir);
  PlotOutcome plots;
  if (!o.no_plots) plots = MakePlots(o.out_dir, review);
  const std::string summary = review.Summary(o.log_path, read, plots.written, plots.notes);
  std::ofstream(o.out_dir + "/summary.txt") << summary;
  std::printf("%s\nsnapthread-report: wrote %s/summary.txt, CSV files and %zu plots\n", summary.c_str(),
              o.out_dir.c_str(), plots.written.size());
  if (read.Partial()) {
    std::fprintf(stderr,
                 "snapthread-report: WARNING: partial report: the log is damaged or truncated "
                 "(%lld of %lld bytes unreadable); the report covers the %lld intact events\n",
                 static_cast<long long>(read.skipped_bytes), static_cast<long long>(read.file_bytes),
                 static_cast<long long>(read.events));
  }
  return app::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  ReportOptions o;
  CLI::App cli{"snapthread-report: turns an LCM log of a snapthread session into CSV files, "
               "gnuplot PNG plots and summary.txt"};
  AddReportFlags(&cli, &o);
  if (auto code = app::ParseCommandLine(cli, argc, argv, kExitBadArguments)) return *code;
  if (!o.common.session.empty()) {
    if (auto code = app::CheckCommonFlags(o.common, kProgram, kExitBadArguments)) return *code;
  }
  if (auto code = CheckLogSize(o)) return *code;
  if (o.out_dir.empty()) o.out_dir = o.log_path + ".report";
  if (o.common.session.empty()) {
    if (auto code = InferSessionFromLog(&o)) return *code;
  }
  // A sealed log opens with a credential's read key: loaded only when one is named.
  if (!o.common.key_path.empty() || std::getenv(snapthread::auth::kKeyFileEnv) != nullptr) {
    if (!app::LoadKeySet(o.common, snapthread::auth::Role::kObserver, kProgram)) return app::kExitFailure;
  }
  SessionReview review(o.common.session);
  LogReadStats read;
  if (auto code = ReadReview(o, &review, &read)) return *code;
  return WriteReport(o, review, read);
}
