// snapthread-report on logs written here with lcm::LogFile: known messages with sequence
// gaps, a repeat, a snap and clamps; then the same log truncated or damaged.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "snapthread/command_reply_t.hpp"
#include "snapthread/device_state_t.hpp"
#include "snapthread/device_status_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"
#include "png_image.h"
#include "report_session.h"
#include "test_support.h"

namespace snapthread::viewer_test {
namespace {

using namespace test_support;  // the shared fixtures (tests/support)

constexpr int64_t kT0 = 1700000000000000;  // log time origin, us
constexpr int kModels = 200;
// Force-model sequence numbers left out of the log: one gap of 3 and one of 1.
bool Dropped(int seq) { return (seq >= 50 && seq <= 52) || seq == 120; }

class LogWriter {
 public:
  explicit LogWriter(const std::string& path) : log_(path, "w") {}
  bool good() const { return log_.good(); }
  template <class T>
  void Write(const std::string& channel, int64_t t_us, const T& msg) {
    std::vector<uint8_t> buf(msg.getEncodedSize());
    msg.encode(buf.data(), 0, int(buf.size()));
    WriteRaw(channel, t_us, buf);
  }
  void WriteRaw(const std::string& channel, int64_t t_us, std::vector<uint8_t> data) {
    lcm::LogEvent e;
    e.timestamp = t_us;
    e.channel = channel;
    e.datalen = int32_t(data.size());
    e.data = data.data();
    log_.writeEvent(&e);
  }

 private:
  lcm::LogFile log_;
};

force_model_t Model(int seq) { return ReportModel(seq, kT0); }

// Writes the reference log and returns its path.
std::string WriteReferenceLog(const std::string& dir) {
  const std::string path = dir + "/session.lcmlog";
  LogWriter log(path);
  EXPECT_TRUE(log.good());
  for (int k = 1; k <= kModels; ++k) {
    const int64_t t = kT0 + k * 1000;
    log.Write("RPT_DEVICE_STATE", t, ReportPose(k, "test"));
    if (!Dropped(k)) log.Write("RPT_FORCE_MODEL", t + 700, Model(k));  // 700 us round trip
    if (k == 11) log.Write("RPT_FORCE_MODEL", t + 800, Model(10));   // a late repeat
    if (k % 10 == 0) {
      log.Write("RPT_SHAPE", t + 10, ReportShape(k, t, "test"));
      log.Write("RPT_SOLVER_STATUS", t + 20, ReportSolverStatus(k, t, "test"));
    }
    if (k % 40 == 0) log.Write("RPT_DEVICE_STATUS", t + 30, ReportDeviceStatus(k, "test"));
    if (k % 100 == 0) {  // the server's answers to two commands
      command_reply_t reply{};
      reply.utime = t;
      reply.seq = k / 100;
      reply.command = 1;  // command_t.RESET
      reply.ok = 1;
      reply.message = "RESET: back to the start of scene 'test'";
      log.Write("RPT_COMMAND_REPLY", t + 40, reply);
    }
  }
  log.WriteRaw("OTHER_CHANNEL", kT0 + (kModels + 1) * 1000, {1, 2, 3});
  return path;
}

ProcessResult RunReport(const std::string& log, const std::string& out_dir,
                        const std::vector<std::string>& extra = {}) {
  std::vector<std::string> argv = {BinDir() + "/snapthread-report", log, "--out", out_dir};
  argv.insert(argv.end(), extra.begin(), extra.end());
  ChildProcess report(argv, OutputFiles(out_dir + ".stdout", out_dir + ".stderr", true));
  EXPECT_TRUE(report.started());
  return report.Finish(120.0);
}

std::string Line(const std::string& text, const std::string& start) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(start, 0) == 0) return line;
  }
  return "";
}

// A PNG with real content: valid, plot-sized, many colours and a good share of ink.
void ExpectNonTrivialPng(const std::string& path) {
  Image img;
  std::string error;
  ASSERT_TRUE(ReadPng(path, &img, &error)) << path << ": " << error;
  ExpectRealPlot(img, path);
}

TEST(ReportTest, SummaryCountsGapsForceSnapsAndPlots) {
  const std::string dir = FreshTempDir("report");
  const std::string log = WriteReferenceLog(dir);
  const ProcessResult r = RunReport(log, dir + "/out");
  ASSERT_TRUE(r.exited);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string summary = ReadFile(dir + "/out/summary.txt");
  ASSERT_FALSE(summary.empty());
  EXPECT_NE(summary.find("session: RPT"), std::string::npos) << summary;
  EXPECT_NE(summary.find("read: COMPLETE"), std::string::npos) << summary;
  // 200 models - 4 dropped + 1 repeat; gaps 49->53 (3 missing) and 119->121 (1 missing).
  EXPECT_NE(Line(summary, "channel RPT_FORCE_MODEL ")
                .find("messages 197 rate_hz"), std::string::npos) << summary;
  EXPECT_NE(Line(summary, "channel RPT_FORCE_MODEL ")
                .find("seq 1..200 missing 4 gaps 2 out_of_order 1"), std::string::npos)
      << summary;
  EXPECT_NE(summary.find("gap RPT_FORCE_MODEL 49 -> 53: 3"), std::string::npos) << summary;
  EXPECT_NE(summary.find("gap RPT_FORCE_MODEL 119 -> 121: 1"), std::string::npos) << summary;
  EXPECT_NE(Line(summary, "channel RPT_DEVICE_STATE ")
                .find("messages 200 rate_hz"), std::string::npos) << summary;
  EXPECT_NE(Line(summary, "channel RPT_DEVICE_STATE ").find("missing 0 gaps 0 out_of_order 0"),
            std::string::npos) << summary;
  EXPECT_NE(Line(summary, "channel RPT_SHAPE ").find("messages 20 "), std::string::npos);
  EXPECT_NE(Line(summary, "channel RPT_SOLVER_STATUS ").find("messages 20 "), std::string::npos);
  EXPECT_NE(Line(summary, "channel OTHER_CHANNEL ").find("messages 1 "), std::string::npos);
  EXPECT_NE(Line(summary, "channel RPT_COMMAND_REPLY ").find("type command_reply_t messages 2 "),
            std::string::npos) << summary;
  EXPECT_NE(Line(summary, "channel RPT_COMMAND_REPLY ").find("rejected 0 seq 1..2 missing 0"),
            std::string::npos) << summary;
  EXPECT_NE(summary.find("max_force_n: 2.0000"), std::string::npos) << summary;
  // Models answer poses 1..200 except the 4 dropped; the late repeat answers an older pose.
  EXPECT_NE(summary.find("latest_wins: models answer 196 poses of seq 1..200, skipped_poses 4, "
                         "device_seq_regressions 1"),
            std::string::npos) << summary;
  EXPECT_NE(summary.find("snaps: 1 "), std::string::npos) << summary;
  // The certified force error of the models (1e-6 N x seq, for the scene's only grasp).
  EXPECT_NE(summary.find("force_error_n (certified) grasp -: p50 "), std::string::npos) << summary;
  EXPECT_NE(Line(summary, "force_error_n (certified) grasp -: ").find(" max 0.0002 N; none on 0 of 197 models"),
            std::string::npos) << summary;
  EXPECT_NE(summary.find("shapes count 1"), std::string::npos) << summary;
  EXPECT_NE(summary.find("clamps: force 4 "), std::string::npos) << summary;
  EXPECT_NE(summary.find("methods: newton, higher-order"), std::string::npos) << summary;
  // The knot over time (statuses at log time (k * 1000 + 20 - 1000) us, k = 10, 20, ...).
  EXPECT_NE(summary.find("knot_changes: 0.009 unknot (det 1) 0.149 trefoil (det 3)\n"),
            std::string::npos) << summary;
  EXPECT_NE(summary.find("knot_last: trefoil; contacts max 4 last 4"), std::string::npos)
      << summary;
  EXPECT_NE(summary.find("duration_s: 0.200"), std::string::npos) << summary;
  // Round trip as logged: every answered pose took 700 us (the repeat answers pose 10 late).
  EXPECT_NE(summary.find("round_trip_us (pose logged -> model logged) p50 700"), std::string::npos)
      << summary;
  // The CSV carries every force model in log order.
  std::ifstream csv(dir + "/out/force.csv");
  int rows = -1;
  for (std::string line; std::getline(csv, line);) rows++;
  EXPECT_EQ(rows, 197);
  std::ifstream knot_csv(dir + "/out/knot.csv");
  std::vector<std::string> knot_rows;
  for (std::string line; std::getline(knot_csv, line);) knot_rows.push_back(line);
  ASSERT_EQ(knot_rows.size(), 21u);
  EXPECT_EQ(knot_rows[0], "t_s,knot,knot_determinant,contacts");
  EXPECT_EQ(knot_rows[20], "0.19902,trefoil,3,4");
  for (const char* png :
       {"force.png", "force_error.png", "solver.png", "device.png", "latency_hist.png", "knot.png"}) {
    SCOPED_TRACE(png);
    ExpectNonTrivialPng(dir + "/out/" + png);
  }
}

// The certified force error per grasp: a grasp whose models carry none (-1) is shown as
// "none", in the summary and in force.csv, and its rows are not drawn.
TEST(ReportTest, ForceErrorPerGraspShowsNoneWhereTheServerMadeNoEstimate) {
  const std::string dir = FreshTempDir("report-force-error");
  const std::string path = dir + "/session.lcmlog";
  {
    LogWriter log(path);
    ASSERT_TRUE(log.good());
    for (int k = 1; k <= 20; ++k) {
      force_model_t left = Model(k), right = Model(k);
      left.grasp = "left";
      right.grasp = "right";
      right.force_error_n = -1.0;
      log.Write("RPT_FORCE_MODEL", kT0 + k * 1000, left);
      log.Write("RPT_FORCE_MODEL", kT0 + k * 1000 + 1, right);
    }
  }
  const ProcessResult r = RunReport(path, dir + "/out");
  ASSERT_TRUE(r.exited);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string summary = ReadFile(dir + "/out/summary.txt");
  EXPECT_NE(summary.find("force_error_n (certified) grasp left: p50 "), std::string::npos) << summary;
  EXPECT_NE(Line(summary, "force_error_n (certified) grasp left: ").find(" max 2e-05 N; none on 0 of 20 models"),
            std::string::npos) << summary;
  EXPECT_NE(summary.find("force_error_n (certified) grasp right: none; none on 20 of 20 models\n"),
            std::string::npos) << summary;
  std::ifstream csv(dir + "/out/force.csv");
  std::vector<std::string> rows;
  for (std::string line; std::getline(csv, line);) rows.push_back(line);
  ASSERT_EQ(rows.size(), 41u);
  EXPECT_EQ(rows[0], "t_s,fx_n,fy_n,fz_n,f_norm_n,status,seq,grasp_index,force_error_n");
  EXPECT_EQ(rows[2].substr(rows[2].rfind(',', rows[2].rfind(',') - 1)), ",1,none") << rows[2];
  ExpectNonTrivialPng(dir + "/out/force_error.png");
}

// A damaged log still gives a report (exit 0), marked partial with a warning.
void RunPartialReport(const std::string& log, const std::string& dir, std::string* summary) {
  const ProcessResult r = RunReport(log, dir + "/out");
  ASSERT_TRUE(r.exited);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("WARNING: partial report"), std::string::npos) << r.err;
  *summary = ReadFile(dir + "/out/summary.txt");
  EXPECT_NE(summary->find("read: PARTIAL"), std::string::npos) << *summary;
}

TEST(ReportTest, TruncatedLogGivesAPartialReportWithAWarning) {
  const std::string dir = FreshTempDir("report-trunc");
  const std::string log = WriteReferenceLog(dir);
  const auto size = std::filesystem::file_size(log);
  // Cut inside the last event (the 3-byte OTHER_CHANNEL message).
  std::filesystem::resize_file(log, size - 5);
  std::string summary;
  ASSERT_NO_FATAL_FAILURE(RunPartialReport(log, dir, &summary));
  EXPECT_NE(summary.find("truncated log"), std::string::npos) << summary;
  // Everything before the cut is reported.
  EXPECT_NE(Line(summary, "channel RPT_FORCE_MODEL ").find("messages 197 "), std::string::npos)
      << summary;
  EXPECT_EQ(Line(summary, "channel OTHER_CHANNEL "), "") << summary;
  ExpectNonTrivialPng(dir + "/out/force.png");
}

TEST(ReportTest, DamagedMiddleIsSkippedAndTheRestStillRead) {
  const std::string dir = FreshTempDir("report-damage");
  const std::string log = WriteReferenceLog(dir);
  const auto size = std::filesystem::file_size(log);
  {
    std::fstream f(log, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(size / 2));
    // Longer than any one event (a force model with its 6x6 wrench block is ~0.8 kB), so
    // the damage reaches an event header wherever it lands.
    const std::string junk(2000, '\xAB');
    f.write(junk.data(), std::streamsize(junk.size()));
  }
  std::string summary;
  ASSERT_NO_FATAL_FAILURE(RunPartialReport(log, dir, &summary));
  // The last event (after the damage) is still there; a few in the middle are lost.
  EXPECT_NE(Line(summary, "channel OTHER_CHANNEL ").find("messages 1 "), std::string::npos)
      << summary;
  const std::string fm = Line(summary, "channel RPT_FORCE_MODEL ");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(fm, m, std::regex("messages (\\d+) ")));
  const int n = std::stoi(m[1]);
  EXPECT_LT(n, 197);
  EXPECT_GT(n, 170);
}

TEST(ReportTest, NothingReadableExitsNonZero) {
  const std::string dir = FreshTempDir("report-junk");
  const std::string log = dir + "/junk.lcmlog";
  std::ofstream(log) << std::string(4000, 'x');
  const ProcessResult r = RunReport(log, dir + "/out");
  ASSERT_TRUE(r.exited);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no readable events"), std::string::npos) << r.err;
}

// A log above --max-log-bytes is refused before it is read, naming its size and the limit.
TEST(ReportTest, RefusesALogLargerThanTheLimit) {
  const std::string dir = FreshTempDir("report-size");
  const std::string log = WriteReferenceLog(dir);
  const auto size = std::filesystem::file_size(log);
  const ProcessResult r = RunReport(log, dir + "/out", {"--max-log-bytes", std::to_string(size - 1)});
  ASSERT_TRUE(r.exited);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(log + " is " + std::to_string(size) + " bytes, larger than the limit of " +
                       std::to_string(size - 1) + " bytes (--max-log-bytes)"),
            std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/out/summary.txt"));
  // At the limit it is read.
  const ProcessResult ok = RunReport(log, dir + "/out", {"--max-log-bytes", std::to_string(size), "--no-plots"});
  ASSERT_TRUE(ok.exited);
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
}

// The default limit is 2 GiB: a 3 GiB (sparse) log is refused at once, not read for minutes.
TEST(ReportTest, RefusesAThreeGibLogByDefault) {
  const std::string dir = FreshTempDir("report-huge");
  const std::string log = WriteReferenceLog(dir);
  std::filesystem::resize_file(log, uint64_t(3) << 30);
  const auto t0 = std::chrono::steady_clock::now();
  const ProcessResult r = RunReport(log, dir + "/out");
  ASSERT_TRUE(r.exited);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("3221225472 bytes, larger than the limit of 2147483648 bytes"),
            std::string::npos) << r.err;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
            10.0 * SpeedScale());
}

// A log with ever new channel names lists the first 1000 and counts the rest.
TEST(ReportTest, ListsAtMostAThousandChannels) {
  const std::string dir = FreshTempDir("report-channels");
  const std::string log = WriteReferenceLog(dir);
  {
    std::ofstream f(log, std::ios::binary | std::ios::app);
    for (int i = 0; i < 1500; ++i) {
      const std::string channel = "FLOOD_" + std::to_string(i);
      std::string e = {'\xED', '\xA1', '\xDA', '\x01', 0, 0, 0, 0, 0, 0, 0, 0};
      for (int k = 7; k >= 0; --k) e.push_back(char(((kT0 + 300000 + i) >> (8 * k)) & 0xff));
      for (uint32_t v : {uint32_t(channel.size()), 1u}) {
        for (int k = 3; k >= 0; --k) e.push_back(char((v >> (8 * k)) & 0xff));
      }
      e += channel + "x";
      f.write(e.data(), std::streamsize(e.size()));
    }
  }
  const ProcessResult r = RunReport(log, dir + "/out", {"--no-plots"});
  ASSERT_TRUE(r.exited);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string summary = ReadFile(dir + "/out/summary.txt");
  // The session's 6 channels and OTHER_CHANNEL come first; 993 flood channels fill the table.
  EXPECT_NE(summary.find("channels beyond the first 1000: 507 messages (507 bytes), not listed"),
            std::string::npos) << summary.substr(0, 2000);
  EXPECT_NE(summary.find("session: RPT\n"), std::string::npos);
}

}  // namespace
}  // namespace snapthread::viewer_test
