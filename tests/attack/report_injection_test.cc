// A hostile log against snapthread-report (docs/security.md, "every byte hostile where
// displayed"). The real snapthread-logger records a genuine session LAB1 while a keyless
// sender publishes valid force models, more of them than the genuine session sends, on
// channels whose names are shell and gnuplot commands, so that a report that takes the
// busiest <SESSION>_<SUFFIX> as the session pastes them into its gnuplot titles. Names LCM
// does not deliver to a ".*" subscriber (newlines, non-UTF-8) or not send (longer than 63
// bytes) are appended to the recorded log as extra events: a log is a file anyone can hand
// over. Each case asserts that no marker file appears anywhere, that the report completes
// with the genuine session's plots (pixel for pixel those of the same log without the
// hostile channels), and that the hostile name shows up only escaped.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "messages/channels.h"
#include "png_image.h"
#include "report_session.h"
#include "snapthread/device_state_t.hpp"
#include "snapthread/device_status_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"
#include "test_support.h"

namespace snapthread::attack_test {
namespace {

using namespace test_support;
namespace fs = std::filesystem;

constexpr int kModels = 200;       // genuine force models
constexpr int kHostileModels = 600;  // more than the whole genuine session (445 messages)
const char* const kPlots[] = {"force.png", "force_error.png", "knot.png", "solver.png", "device.png",
                              "latency_hist.png"};

// A port of its own, away from the shared group's traffic and the logger tests' ports.
std::string PrivateUrl() {
  return "udpm://239.255.76.67:" + std::to_string(7900 + getpid() % 100) + "?ttl=0";
}

template <class T>
std::vector<uint8_t> Encode(const T& msg) {
  std::vector<uint8_t> buf(size_t(msg.getEncodedSize()));
  msg.encode(buf.data(), 0, int(buf.size()));
  return buf;
}

// A genuine force model: its server times from 0 (the logger stamps the log itself).
force_model_t Model(int seq) { return ReportModel(seq, 0); }

using Message = std::pair<std::string, std::vector<uint8_t>>;

// The genuine session LAB1: poses, force models, shapes, solver and device statuses.
std::vector<Message> GenuineSession() {
  std::vector<Message> out;
  for (int k = 1; k <= kModels; ++k) {
    out.emplace_back("LAB1_DEVICE_STATE", Encode(ReportPose(k, "lab")));
    out.emplace_back("LAB1_FORCE_MODEL", Encode(Model(k)));
    if (k % 10 == 0) {
      out.emplace_back("LAB1_SHAPE", Encode(ReportShape(k, k * 1000, "curve2d_snap")));
      out.emplace_back("LAB1_SOLVER_STATUS", Encode(ReportSolverStatus(k, k * 1000, "curve2d_snap")));
    }
    if (k % 40 == 0) out.emplace_back("LAB1_DEVICE_STATUS", Encode(ReportDeviceStatus(k, "lab")));
  }
  return out;
}

bool IsGenuine(const std::string& channel) {
  static const std::set<std::string> kGenuine = {"LAB1_DEVICE_STATE", "LAB1_FORCE_MODEL",
                                                 "LAB1_SHAPE", "LAB1_SOLVER_STATUS",
                                                 "LAB1_DEVICE_STATUS"};
  return kGenuine.count(channel) > 0;
}

// One hostile channel. Over the network when LCM delivers such a name to a ".*" subscriber;
// else appended to the recorded log.
struct Hostile {
  const char* label;
  std::string channel;
  bool over_network;
};

// gtest names a case by its label (the bytes of the name would garble the log).
void PrintTo(const Hostile& h, std::ostream* os) { *os << h.label; }

std::string Padded(const std::string& head, size_t total, char fill) {
  const std::string tail = "_FORCE_MODEL";
  return head + std::string(total - head.size() - tail.size(), fill) + tail;
}

std::vector<Hostile> HostileChannels() {
  return {
      {"system", "LAB1_';system \"id>pwned\"#_FORCE_MODEL", true},
      {"backticks", "LAB1_`touch pwned_bq`_FORCE_MODEL", true},
      {"dollar", "LAB1_$(touch pwned_dl)_FORCE_MODEL", true},
      {"set_output_pipe", "LAB1_';set output \"|touch pwned_pp\";#_FORCE_MODEL", true},
      {"longest_on_the_wire", Padded("LAB1_';system \"touch pwned_lg\"#", 63, 'A'), true},
      {"newline", "LAB1_'\nsystem \"touch pwned_nl\"\n#_FORCE_MODEL", false},
      {"newline_set_output_pipe", "LAB1_'\nset output \"|touch pwned_np\"\n#_FORCE_MODEL", false},
      {"non_utf8", "LAB1_\xff\xfe';system \"touch pwned_u8\"#_FORCE_MODEL", false},
      {"very_long_in_the_file", Padded("LAB1_';system \"touch pwned_vl\"#", 900, 'B'), false},
  };
}

std::map<std::string, int> CountEvents(const std::string& path) {
  std::map<std::string, int> counts;
  lcm::LogFile log(path, "r");
  if (!log.good()) return counts;
  while (const lcm::LogEvent* e = log.readNextEvent()) counts[e->channel]++;
  return counts;
}

void PutBigEndian(uint64_t v, int bytes, std::string* out) {
  for (int i = bytes - 1; i >= 0; --i) out->push_back(char((v >> (8 * i)) & 0xff));
}

// Appends events in lcm-logger's format (what a hand-made hostile log holds).
void AppendEvents(const std::string& path, const std::vector<Message>& events, int64_t t_us) {
  std::ofstream f(path, std::ios::binary | std::ios::app);
  for (const auto& [channel, data] : events) {
    std::string e;
    PutBigEndian(0xEDA1DA01, 4, &e);
    PutBigEndian(0, 8, &e);
    PutBigEndian(uint64_t(t_us++), 8, &e);
    PutBigEndian(channel.size(), 4, &e);
    PutBigEndian(data.size(), 4, &e);
    e += channel;
    e.append(reinterpret_cast<const char*>(data.data()), data.size());
    f.write(e.data(), std::streamsize(e.size()));
  }
}

// The same log without the hostile channel: what the plots must look like.
void WriteWithout(const std::string& from, const std::string& to, const std::string& hostile) {
  lcm::LogFile in(from, "r");
  lcm::LogFile out(to, "w");
  ASSERT_TRUE(in.good() && out.good());
  while (const lcm::LogEvent* e = in.readNextEvent()) {
    if (e->channel == hostile) continue;
    lcm::LogEvent copy = *e;
    out.writeEvent(&copy);
  }
}

// Records the genuine session with the real logger while `hostile` (if over the network)
// publishes kHostileModels force models; returns the log's path.
std::string Record(const std::string& dir, const Hostile* hostile) {
  const std::string log_path = dir + "/session.lcmlog";
  const std::string url = PrivateUrl();
  lcm::LCM lcm(url);
  EXPECT_TRUE(lcm.good()) << "LCM udpm does not start (deploy/multicast-route.sh)";
  ChildProcess logger({BinDir() + "/snapthread-logger", "--lcm-url", url, "--flush-interval", "20",
                       log_path},
                      OneLog(dir + "/logger.txt"));
  const uint8_t byte = 0;
  const bool ready = WaitUntil(
      [&] {
        lcm.publish("LAB1_PROBE", &byte, 1);
        return CountEvents(log_path).count("LAB1_PROBE") > 0 || !logger.running();
      },
      20.0 * SpeedScale(), 0.05);
  EXPECT_TRUE(ready && logger.running()) << "logger did not start: " << logger.Out();
  const std::vector<Message> genuine = GenuineSession();
  const std::vector<uint8_t> forged = Encode(Model(7));  // a valid model: it decodes
  int hostile_sent = 0;
  for (size_t i = 0; i < genuine.size(); ++i) {
    lcm.publish(genuine[i].first, genuine[i].second.data(), int(genuine[i].second.size()));
    // The keyless sender: a little more than one message per genuine one.
    while (hostile != nullptr && hostile->over_network &&
           hostile_sent < int((i + 1) * kHostileModels / genuine.size())) {
      EXPECT_EQ(lcm.publish(hostile->channel, forged.data(), int(forged.size())), 0);
      hostile_sent++;
    }
    if (i % 50 == 49) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_TRUE(WaitUntil(
      [&] {
        lcm.publish("LAB1_END", &byte, 1);
        return CountEvents(log_path).count("LAB1_END") > 0;
      },
      20.0 * SpeedScale(), 0.05));
  logger.Signal(SIGINT);
  int code = -1;
  EXPECT_TRUE(logger.Wait(10.0 * SpeedScale(), &code));
  EXPECT_EQ(code, 0) << logger.Out();
  if (hostile != nullptr && !hostile->over_network) {
    AppendEvents(log_path, std::vector<Message>(kHostileModels, {hostile->channel, forged}),
                 int64_t(4e15));
  }
  return log_path;
}

// Runs snapthread-report in `cwd` (where a `system` in a gnuplot script would write).
ProcessResult RunReport(const std::string& cwd, const std::vector<std::string>& args,
                        const std::string& out_prefix) {
  std::vector<std::string> argv = {BinDir() + "/snapthread-report"};
  argv.insert(argv.end(), args.begin(), args.end());
  const fs::path here = fs::current_path();
  fs::current_path(cwd);
  ChildProcess report(argv, OutputFiles(out_prefix + ".stdout", out_prefix + ".stderr", true));
  fs::current_path(here);
  EXPECT_TRUE(report.started());
  return report.Finish(180.0);
}

// Every file under `root` whose name starts with "pwned": what an injected command made.
std::vector<std::string> Markers(const std::string& root) {
  std::vector<std::string> found;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (entry.path().filename().string().rfind("pwned", 0) == 0) found.push_back(entry.path());
  }
  return found;
}

std::string Line(const std::string& text, const std::string& start) {
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(start, 0) == 0) return line;
  }
  return "";
}

bool PrintableLines(const std::string& text) {
  return std::all_of(text.begin(), text.end(), [](char c) {
    return c == '\n' || (static_cast<unsigned char>(c) >= 0x20 && static_cast<unsigned char>(c) < 0x7f);
  });
}

class ReportInjectionTest : public ::testing::TestWithParam<Hostile> {
 protected:
  void SetUp() override { ASSERT_FALSE(BinDir().empty()) << "run through ctest"; }
};

TEST_P(ReportInjectionTest, RunsNoCommandDrawsTheGenuineSessionAndEscapesTheName) {
  const Hostile& h = GetParam();
  ScopedTempDir root("attack-report");
  const std::string dir = root.path();
  const std::string cwd = dir + "/cwd";
  fs::create_directories(cwd);
  const std::string log = Record(dir, &h);
  const std::map<std::string, int> counts = CountEvents(log);
  ASSERT_EQ(counts.count(h.channel), 1u) << "the hostile channel is not in the log";
  const int hostile_logged = counts.at(h.channel);
  const int genuine_models = counts.count("LAB1_FORCE_MODEL") ? counts.at("LAB1_FORCE_MODEL") : 0;
  int genuine_total = 0;
  for (const auto& [channel, n] : counts) genuine_total += IsGenuine(channel) ? n : 0;
  // The attack needs the hostile "session" to be the busiest one.
  ASSERT_GT(hostile_logged, genuine_total) << "the hostile channel is not the busiest";
  ASSERT_GT(genuine_models, kModels * 9 / 10);

  const ProcessResult r = RunReport(cwd, {log, "--out", dir + "/out"}, dir + "/report");
  const std::vector<std::string> markers = Markers(dir);
  EXPECT_TRUE(markers.empty()) << "an injected command ran: " << markers.front();
  ASSERT_TRUE(r.exited);
  ASSERT_EQ(r.exit_code, 0) << r.err;

  // The genuine session is the one reviewed, with every plot.
  const std::string summary = ReadFile(dir + "/out/summary.txt");
  EXPECT_NE(summary.find("\nsession: LAB1\n"), std::string::npos) << summary;
  EXPECT_NE(summary.find("plots: force.png force_error.png knot.png solver.png device.png latency_hist.png\n"),
            std::string::npos) << summary;
  std::ifstream csv(dir + "/out/force.csv");
  int rows = -1;
  for (std::string line; std::getline(csv, line);) rows++;
  EXPECT_EQ(rows, genuine_models);

  // The name is shown escaped, never raw, and the text output is one printable line per item.
  const std::string escaped = messages::EscapeForDisplay(h.channel);
  EXPECT_NE(Line(summary, "channel " + escaped + " ").find("messages " + std::to_string(hostile_logged) + " "),
            std::string::npos) << summary;
  EXPECT_NE(r.out.find("channel " + escaped + " "), std::string::npos);
  EXPECT_EQ(summary.find(h.channel), std::string::npos) << "raw hostile name in summary.txt";
  EXPECT_EQ(r.out.find(h.channel), std::string::npos) << "raw hostile name on stdout";
  EXPECT_TRUE(PrintableLines(summary)) << summary;
  EXPECT_TRUE(PrintableLines(ReadFile(dir + "/out/channels.csv")));
  if (std::string(h.label) == "system") {
    // Spelled out once, independent of EscapeForDisplay: each byte outside the grammar as \xNN.
    EXPECT_NE(summary.find("channel LAB1_\\x27\\x3bsystem\\x20\\x22id\\x3epwned\\x22\\x23_FORCE_MODEL "
                           "type - messages " + std::to_string(hostile_logged) + " "),
              std::string::npos) << summary;
  }

  // The scripts hold no text of the log and are private; gnuplot's logs too.
  for (const char* png : kPlots) {
    const std::string stem = std::string(png).substr(0, std::string(png).size() - 4);
    const std::string script = ReadFile(dir + "/out/" + stem + ".gp");
    EXPECT_FALSE(script.empty()) << stem;
    EXPECT_EQ(script.find("pwned"), std::string::npos) << script;
    EXPECT_EQ(script.find(dir), std::string::npos) << "a path in " << stem << ".gp";
    struct stat st {};
    ASSERT_EQ(stat((dir + "/out/" + stem + ".gp").c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0077, 0u) << stem << ".gp is readable by others";
  }

  // The plots are the genuine session's: pixel for pixel those of the log without the
  // hostile channel.
  const std::string clean = dir + "/genuine.lcmlog";
  ASSERT_NO_FATAL_FAILURE(WriteWithout(log, clean, h.channel));
  const ProcessResult rc = RunReport(cwd, {clean, "--out", dir + "/clean"}, dir + "/clean");
  ASSERT_TRUE(rc.exited);
  ASSERT_EQ(rc.exit_code, 0) << rc.err;
  for (const char* png : kPlots) {
    SCOPED_TRACE(png);
    viewer_test::Image got, want;
    std::string error;
    ASSERT_TRUE(viewer_test::ReadPng(dir + "/out/" + png, &got, &error)) << error;
    ASSERT_TRUE(viewer_test::ReadPng(dir + "/clean/" + png, &want, &error)) << error;
    ExpectRealPlot(got, png);
    EXPECT_EQ(got.width, want.width);
    EXPECT_EQ(got.height, want.height);
    EXPECT_TRUE(got.rgb == want.rgb) << png << " differs from the genuine session's plot";
  }
  EXPECT_TRUE(Markers(dir).empty());
}

INSTANTIATE_TEST_SUITE_P(HostileChannelNames, ReportInjectionTest,
                         ::testing::ValuesIn(HostileChannels()),
                         [](const ::testing::TestParamInfo<Hostile>& info) {
                           return std::string(info.param.label);
                         });

// A hostile --session is refused at start-up, before the log is read.
TEST(ReportInjectionCliTest, RefusesASessionOutsideTheGrammar) {
  ScopedTempDir root("attack-report-cli");
  const std::string dir = root.path();
  const std::string log = dir + "/any.lcmlog";
  AppendEvents(log, {{"LAB1_PROBE", {0}}}, 1);
  for (const std::string& session : std::vector<std::string>{
           "LAB1';system \"touch pwned_s\"#", "LAB1\nX", "LAB 1", "", std::string(64, 'S')}) {
    SCOPED_TRACE(session);
    const ProcessResult r =
        RunReport(dir, {log, "--session", session, "--out", dir + "/out"}, dir + "/report");
    ASSERT_TRUE(r.exited);
    if (session.empty()) continue;  // "" means: infer it
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("bad --session"), std::string::npos) << r.err;
    EXPECT_TRUE(PrintableLines(r.err)) << r.err;
  }
  EXPECT_TRUE(Markers(dir).empty());
}

// A log whose file name is a gnuplot command: the default output directory (LOG.report)
// carries it, and no script names a path.
TEST(ReportInjectionCliTest, AHostileLogFileNameReachesNoScript) {
  ScopedTempDir root("attack-report-path");
  const std::string dir = root.path();
  const std::string log = Record(dir, nullptr);
  const std::string hostile_log = dir + "/x';system \"touch pwned_path\"#.lcmlog";
  fs::copy_file(log, hostile_log);
  const ProcessResult r = RunReport(dir, {hostile_log}, dir + "/report");
  EXPECT_TRUE(Markers(dir).empty()) << "an injected command ran";
  ASSERT_TRUE(r.exited);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* png : kPlots) {
    viewer_test::Image img;
    std::string error;
    ASSERT_TRUE(viewer_test::ReadPng(hostile_log + ".report/" + png, &img, &error)) << png << error;
    ExpectRealPlot(img, png);
  }
}

// The viewer's live rates print channel names from the network: escaped, one printable
// line each, so a name cannot forge lines or send terminal escape sequences.
TEST(ReportInjectionViewerTest, PrintRatesShowsHostileChannelNamesEscaped) {
  ScopedTempDir root("attack-viewer-rates");
  const std::string dir = root.path();
  SessionKeyFile key;  // the viewer checks shapes and statuses with it
  const std::string url = PrivateUrl();
  lcm::LCM lcm(url);
  ASSERT_TRUE(lcm.good());
  std::vector<std::string> hostile;
  for (const Hostile& h : HostileChannels()) {
    if (h.over_network) hostile.push_back(h.channel);
  }
  hostile.push_back("LAB1_\x1b]0;owned\x07\x1b[2J_SHAPE");  // retitles and clears a terminal
  ChildProcess viewer({BinDir() + "/snapthread-viewer", "--print-rates", "--session", "LAB1",
                       "--lcm-url", url, "--duration-s", "3"},
                      OutputFiles(dir + "/viewer.out", dir + "/viewer.err"));
  ASSERT_TRUE(viewer.WaitForOutput("channel rates", 20.0 * SpeedScale())) << viewer.Err();
  const std::vector<uint8_t> forged = Encode(Model(7));
  const auto t0 = std::chrono::steady_clock::now();
  while (viewer.running() && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5)) {
    for (const std::string& channel : hostile) lcm.publish(channel, forged.data(), int(forged.size()));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const ProcessResult r = viewer.Finish(20.0 * SpeedScale());
  ASSERT_TRUE(r.exited);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(PrintableLines(r.out)) << r.out;
  for (const std::string& channel : hostile) {
    SCOPED_TRACE(messages::EscapeForDisplay(channel));
    EXPECT_NE(r.out.find("TOTAL " + messages::EscapeForDisplay(channel) + " "), std::string::npos)
        << r.out;
    EXPECT_EQ(r.out.find(channel), std::string::npos) << "raw name printed";
  }
  EXPECT_TRUE(Markers(dir).empty());
}

// The grammar and the escaping the report and the viewer rely on (common/messages/channels.h).
TEST(ChannelGrammarTest, AcceptsTheProjectsNamesAndRefusesEverythingElse) {
  for (const std::string& ok : std::vector<std::string>{"LAB1_FORCE_MODEL", "SNAPTHREAD_DEVICE_STATUS", "LCM_SELF_TEST",
                               "a.b:c/d-e", std::string(63, 'S')}) {
    EXPECT_TRUE(messages::IsValidChannelName(ok)) << ok;
    EXPECT_EQ(messages::EscapeForDisplay(ok), ok);
  }
  for (const Hostile& h : HostileChannels()) EXPECT_FALSE(messages::IsValidChannelName(h.channel));
  for (const std::string& bad : std::vector<std::string>{"", std::string(64, 'S'), "A B", "A\tB", "\xc3\xa4", "A\\B"}) {
    EXPECT_FALSE(messages::IsValidChannelName(bad)) << messages::EscapeForDisplay(bad);
  }
}

TEST(ChannelGrammarTest, EscapingIsPrintableOneLineAndKeepsBytesApart) {
  std::set<std::string> seen;
  for (int b = 0; b < 256; ++b) {
    const std::string one(1, char(b));
    const std::string shown = messages::EscapeForDisplay("x" + one + "y");
    EXPECT_TRUE(PrintableLines(shown) && shown.find('\n') == std::string::npos) << b;
    for (char c : std::string("'\"`$;|# ,")) EXPECT_EQ(shown.find(c), std::string::npos) << b;
    EXPECT_TRUE(seen.insert(shown).second) << "two bytes escape alike: " << shown;
  }
  EXPECT_EQ(messages::EscapeForDisplay("\\x41"), "\\x5cx41");  // a backslash is escaped too
  const std::string shown = messages::EscapeForDisplay(std::string(900, 'B'));
  EXPECT_EQ(shown, std::string(128, 'B') + "...[900 bytes]");
}

}  // namespace
}  // namespace snapthread::attack_test
