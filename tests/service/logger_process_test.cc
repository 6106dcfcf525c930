// snapthread-logger as a process: it keeps every message of a burst that arrives while it
// is off the CPU (the loss lcm-logger shows under load: liblcm's reader thread drops what
// the subscription's 30-message queue cannot hold), closes a readable log within 1 s of
// SIGINT or SIGTERM, and refuses to overwrite a file unless told to. Its files are private
// (0600), split at --max-bytes and rotated with --rotate without losing a message, and
// its queue is bounded in bytes, counting what it drops.
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "test_support.h"

namespace snapthread {
namespace {

using Clock = std::chrono::steady_clock;
using test_support::ChildProcess;

// A port of its own, so other tests' traffic on the shared group does not fill the stopped
// logger's kernel buffer.
std::string PrivateUrl() {
  return "udpm://239.255.76.67:" + std::to_string(7800 + getpid() % 100) + "?ttl=0";
}

// Messages that fit half of the kernel buffer the logger gets (8 MiB capped by
// net.core.rmem_max, doubled by the kernel; 1,280 bytes per loopback datagram), at most 3000.
int BurstSize() {
  long rmem_max = 212992;
  std::ifstream("/proc/sys/net/core/rmem_max") >> rmem_max;
  const long granted = 2 * std::min<long>(rmem_max, 8 * 1024 * 1024);
  return static_cast<int>(std::clamp<long>(granted / 1280 / 2, 100, 3000));
}

// The BURST messages in the log, by their counter.
std::vector<uint32_t> LoggedBurst(const std::string& path, const std::string& channel) {
  std::vector<uint32_t> seen;
  lcm::LogFile log(path, "r");
  if (!log.good()) return seen;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->channel != channel || e->datalen != 4) continue;
    uint32_t k = 0;
    std::memcpy(&k, e->data, 4);
    seen.push_back(k);
  }
  return seen;
}

class LoggerProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(test_support::BinDir().empty()) << "run through ctest";
    dir_ = test_support::FreshTempDir("logger");
    session_ = test_support::UniqueSession("LOG");
    ASSERT_TRUE(lcm_.good()) << "LCM udpm does not start (deploy/multicast-route.sh)";
  }
  // Starts the logger on this session and waits until probes reach its file.
  // `first_file` is where the probes land (LOG, or LOG.0 with --rotate).
  std::unique_ptr<ChildProcess> StartLogger(const std::string& log_path,
                                            const std::vector<std::string>& extra = {},
                                            std::string first_file = "") {
    std::vector<std::string> argv = {test_support::BinDir() + "/snapthread-logger", "-c",
                                     session_ + "_.*", "--lcm-url", url_, "--flush-interval", "20"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    argv.push_back(log_path);
    if (first_file.empty()) first_file = log_path;
    auto logger = std::make_unique<ChildProcess>(argv, test_support::OneLog(dir_ + "/logger.txt"));
    const std::string probe = session_ + "_PROBE";
    const uint8_t byte = 0;
    const bool ready = test_support::WaitUntil(
        [&] {
          lcm_.publish(probe, &byte, 1);
          // A probe in the file (not just bytes: a file taken over with --force has some).
          lcm::LogFile f(first_file, "r");
          const lcm::LogEvent* e = f.good() ? f.readNextEvent() : nullptr;
          return (e != nullptr && e->channel == probe) || !logger->running();
        },
        20.0, 0.05);
    EXPECT_TRUE(ready && logger->running()) << "logger did not start: " << logger->Out();
    return logger;
  }

  std::string dir_;
  std::string session_;
  const std::string url_ = PrivateUrl();
  lcm::LCM lcm_{PrivateUrl()};
};

mode_t ModeOf(const std::string& path) {
  struct stat st {};
  return stat(path.c_str(), &st) == 0 ? st.st_mode & 07777 : 0;
}

// Publishes `count` 4-byte counters on `channel`, pausing now and then so that loopback
// keeps up, and waits until the logger has them all in its files (via `logged`).
void PublishCounters(lcm::LCM& lcm, const std::string& channel, uint32_t count, size_t pad = 0) {
  std::vector<uint8_t> msg(4 + pad, 0x5a);
  for (uint32_t k = 0; k < count; ++k) {
    std::memcpy(msg.data(), &k, 4);
    ASSERT_EQ(lcm.publish(channel, msg.data(), int(msg.size())), 0);
    if (k % 100 == 99) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

// The counters of `channel` in one log file, in file order (any message of 4 + pad bytes).
std::vector<uint32_t> Counters(const std::string& path, const std::string& channel) {
  std::vector<uint32_t> seen;
  lcm::LogFile log(path, "r");
  if (!log.good()) return seen;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->channel != channel || e->datalen < 4) continue;
    uint32_t k = 0;
    std::memcpy(&k, e->data, 4);
    seen.push_back(k);
  }
  return seen;
}

TEST_F(LoggerProcessTest, KeepsEveryMessageOfABurstThatArrivedWhileItWasStopped) {
  const std::string log_path = dir_ + "/burst.lcmlog";
  auto logger = StartLogger(log_path);
  ASSERT_TRUE(logger->running());
  // Off the CPU (all its threads), as a loaded machine does for tens of ms at a time: the
  // burst waits in the kernel buffer, and on SIGCONT liblcm's reader thread drains it far
  // faster than the handler writes.
  const int burst = BurstSize();
  const std::string channel = session_ + "_BURST";
  logger->Signal(SIGSTOP);
  for (uint32_t k = 0; k < uint32_t(burst); ++k) ASSERT_EQ(lcm_.publish(channel, &k, 4), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  logger->Signal(SIGCONT);
  ASSERT_TRUE(test_support::WaitUntil([&] { return LoggedBurst(log_path, channel).size() >= size_t(burst); },
                                      20.0, 0.1))
      << "logged " << LoggedBurst(log_path, channel).size() << " of " << burst;
  const auto t0 = Clock::now();
  logger->Signal(SIGINT);
  int code = -1;
  ASSERT_TRUE(logger->Wait(5.0, &code));
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 1.0);
  EXPECT_EQ(code, 0) << logger->Out();
  const std::vector<uint32_t> seen = LoggedBurst(log_path, channel);
  ASSERT_EQ(seen.size(), size_t(burst));
  for (uint32_t k = 0; k < seen.size(); ++k) ASSERT_EQ(seen[k], k) << "out of order at " << k;
}

TEST_F(LoggerProcessTest, EndsWithinOneSecondOfSigtermWithTheLogClosed) {
  const std::string log_path = dir_ + "/term.lcmlog";
  auto logger = StartLogger(log_path);
  ASSERT_TRUE(logger->running());
  const auto t0 = Clock::now();
  logger->Signal(SIGTERM);
  int code = -1;
  ASSERT_TRUE(logger->Wait(5.0, &code));
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 1.0);
  EXPECT_EQ(code, 0) << logger->Out();
  EXPECT_NE(logger->Out().find("messages"), std::string::npos) << logger->Out();
  lcm::LogFile log(log_path, "r");
  ASSERT_TRUE(log.good());
  EXPECT_NE(log.readNextEvent(), nullptr);  // the probes
}

TEST_F(LoggerProcessTest, RefusesToOverwriteAFileWithoutForce) {
  const std::string log_path = dir_ + "/exists.lcmlog";
  std::ofstream(log_path) << "keep";
  ChildProcess logger({test_support::BinDir() + "/snapthread-logger", "--lcm-url", url_, log_path},
                      test_support::OneLog(dir_ + "/refuse.txt"));
  const test_support::ProcessResult r = logger.Finish(10.0);
  ASSERT_TRUE(r.exited);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find(log_path), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--force"), std::string::npos) << r.out;
  EXPECT_EQ(test_support::ReadFile(log_path), "keep");
}

}  // namespace
}  // namespace snapthread

namespace snapthread {
namespace {

TEST_F(LoggerProcessTest, LogFilesArePrivateEvenUnderAPermissiveUmask) {
  const std::string log_path = dir_ + "/private.lcmlog";
  const mode_t old_umask = umask(0);  // the child inherits it: fopen would give 0666
  auto logger = StartLogger(log_path);
  umask(old_umask);
  ASSERT_TRUE(logger->running());
  EXPECT_EQ(ModeOf(log_path), 0600u) << std::oct << ModeOf(log_path);
  logger->Signal(SIGINT);
  ASSERT_TRUE(logger->Wait(5.0));
  // A file taken over with --force keeps its inode, not its mode.
  const std::string taken = dir_ + "/taken.lcmlog";
  std::ofstream(taken) << "old";
  ASSERT_EQ(chmod(taken.c_str(), 0644), 0);
  auto forced = StartLogger(taken, {"--force"});
  ASSERT_TRUE(forced->running());
  EXPECT_EQ(ModeOf(taken), 0600u) << std::oct << ModeOf(taken);
  forced->Signal(SIGINT);
  int code = -1;
  ASSERT_TRUE(forced->Wait(5.0, &code));
  EXPECT_EQ(code, 0) << forced->Out();
}

TEST_F(LoggerProcessTest, SplitsAtMaxBytesWithoutLosingOrReorderingAMessage) {
  const std::string log_path = dir_ + "/split.lcmlog";
  constexpr int64_t kMaxBytes = 4096;
  auto logger = StartLogger(log_path, {"--max-bytes", std::to_string(kMaxBytes)});
  ASSERT_TRUE(logger->running());
  const std::string channel = session_ + "_SPLIT";
  constexpr uint32_t kCount = 2000;  // 28 + ~40 + 36 bytes an event: ~40 per file, ~50 files
  ASSERT_NO_FATAL_FAILURE(PublishCounters(lcm_, channel, kCount, 32));
  // Collects LOG, LOG.1, LOG.2, ... in order.
  const auto collect = [&](int* files) {
    std::vector<uint32_t> all;
    *files = 0;
    for (int i = 0;; ++i) {
      const std::string path = i == 0 ? log_path : log_path + "." + std::to_string(i);
      if (!std::filesystem::exists(path)) break;
      ++*files;
      const std::vector<uint32_t> part = Counters(path, channel);
      all.insert(all.end(), part.begin(), part.end());
    }
    return all;
  };
  int files = 0;
  test_support::WaitUntil([&] { return collect(&files).size() >= kCount; }, 20.0, 0.1);
  logger->Signal(SIGINT);
  int code = -1;
  ASSERT_TRUE(logger->Wait(5.0, &code));
  EXPECT_EQ(code, 0) << logger->Out();
  const std::vector<uint32_t> all = collect(&files);
  ASSERT_EQ(all.size(), size_t(kCount)) << "messages lost or duplicated across " << files << " files";
  for (uint32_t k = 0; k < kCount; ++k) ASSERT_EQ(all[k], k) << "out of order at " << k;
  EXPECT_GE(files, 20);
  for (int i = 0; i < files; ++i) {
    const std::string path = i == 0 ? log_path : log_path + "." + std::to_string(i);
    EXPECT_LE(std::filesystem::file_size(path), uint64_t(kMaxBytes)) << path;
    EXPECT_EQ(ModeOf(path), 0600u) << path;
  }
  // The summary names the files and counts no loss.
  EXPECT_NE(logger->Out().find(std::to_string(files) + " files"), std::string::npos) << logger->Out();
  EXPECT_NE(logger->Out().find(" 0 dropped"), std::string::npos) << logger->Out();
}

TEST_F(LoggerProcessTest, RotateKeepsTheLastKFilesLikeLcmLogger) {
  const std::string log_path = dir_ + "/rot.lcmlog";
  std::ofstream(log_path + ".0") << "an older log, rotated away";
  auto logger = StartLogger(log_path, {"--max-bytes", "2048", "--rotate", "3"}, log_path + ".0");
  ASSERT_TRUE(logger->running());
  const std::string channel = session_ + "_ROT";
  constexpr uint32_t kCount = 600;
  ASSERT_NO_FATAL_FAILURE(PublishCounters(lcm_, channel, kCount, 32));
  test_support::WaitUntil(
      [&] {
        const auto last = Counters(log_path + ".0", channel);
        return !last.empty() && last.back() == kCount - 1;
      },
      20.0, 0.1);
  logger->Signal(SIGINT);
  int code = -1;
  ASSERT_TRUE(logger->Wait(5.0, &code));
  EXPECT_EQ(code, 0) << logger->Out();
  EXPECT_FALSE(std::filesystem::exists(log_path + ".3"));
  EXPECT_FALSE(std::filesystem::exists(log_path));
  // LOG.2, LOG.1, LOG.0 hold the newest messages, consecutive, ending with the last one.
  std::vector<uint32_t> kept;
  for (const char* suffix : {".2", ".1", ".0"}) {
    ASSERT_TRUE(std::filesystem::exists(log_path + suffix)) << suffix;
    EXPECT_LE(std::filesystem::file_size(log_path + suffix), 2048u) << suffix;
    EXPECT_EQ(ModeOf(log_path + suffix), 0600u) << suffix;
    const auto part = Counters(log_path + suffix, channel);
    kept.insert(kept.end(), part.begin(), part.end());
  }
  ASSERT_FALSE(kept.empty());
  EXPECT_EQ(kept.back(), kCount - 1);
  for (size_t i = 1; i < kept.size(); ++i) ASSERT_EQ(kept[i], kept[i - 1] + 1) << i;
  EXPECT_LT(kept.size(), size_t(kCount));  // older files were deleted: at most 3 x 2048 bytes
}

TEST_F(LoggerProcessTest, QueueIsBoundedInBytesAndCountsWhatItDrops) {
  const std::string log_path = dir_ + "/bounded.lcmlog";
  auto logger = StartLogger(log_path, {"--max-queue-bytes", "16384"});
  ASSERT_TRUE(logger->running());
  // Three messages larger than the whole queue can never be held: dropped and counted;
  // the small ones around them are logged.
  const std::string channel = session_ + "_BIG";
  const std::vector<uint8_t> big(40000, 0xab);
  for (uint32_t k = 0; k < 3; ++k) {
    ASSERT_EQ(lcm_.publish(channel, big.data(), int(big.size())), 0);
    ASSERT_EQ(lcm_.publish(session_ + "_SMALL", &k, 4), 0);
  }
  test_support::WaitUntil([&] { return Counters(log_path, session_ + "_SMALL").size() >= 3; }, 20.0, 0.05);
  logger->Signal(SIGINT);
  int code = -1;
  ASSERT_TRUE(logger->Wait(5.0, &code));
  EXPECT_EQ(code, 0) << logger->Out();
  EXPECT_EQ(Counters(log_path, session_ + "_SMALL").size(), 3u);
  EXPECT_TRUE(Counters(log_path, channel).empty());
  std::smatch m;
  const std::string out = logger->Out();
  ASSERT_TRUE(std::regex_search(out, m, std::regex(R"((\d+) dropped \(queue full, (\d+) bytes)")))
      << out;
  EXPECT_EQ(m[1], "3") << out;
  EXPECT_EQ(m[2], "120000") << out;
}

TEST_F(LoggerProcessTest, RefusesASymbolicLinkAsTheLog) {
  const std::string target = dir_ + "/elsewhere";
  std::ofstream(target) << "keep";
  const std::string link = dir_ + "/link.lcmlog";
  std::filesystem::create_symlink(target, link);
  ChildProcess logger({test_support::BinDir() + "/snapthread-logger", "--force", "--lcm-url", url_, link},
                      test_support::OneLog(dir_ + "/link.txt"));
  const test_support::ProcessResult r = logger.Finish(10.0);
  ASSERT_TRUE(r.exited);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("symbolic link"), std::string::npos) << r.out;
  EXPECT_EQ(test_support::ReadFile(target), "keep");
}

}  // namespace
}  // namespace snapthread
