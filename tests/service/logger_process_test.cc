// snapthread-logger as a process: it keeps every message of a burst that arrives while it
// is off the CPU (the loss lcm-logger shows under load: liblcm's reader thread drops what
// the subscription's 30-message queue cannot hold), closes a readable log within 1 s of
// SIGINT or SIGTERM, and refuses to overwrite a file unless told to.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
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
  std::unique_ptr<ChildProcess> StartLogger(const std::string& log_path) {
    auto logger = std::make_unique<ChildProcess>(
        std::vector<std::string>{test_support::BinDir() + "/snapthread-logger", "-c", session_ + "_.*",
                                 "--lcm-url", url_, "--flush-interval", "20", log_path},
        test_support::OneLog(dir_ + "/logger.txt"));
    const std::string probe = session_ + "_PROBE";
    const uint8_t byte = 0;
    const bool ready = test_support::WaitUntil(
        [&] {
          lcm_.publish(probe, &byte, 1);
          std::ifstream f(log_path, std::ios::ate | std::ios::binary);
          return (f && f.tellg() > 0) || !logger->running();
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
