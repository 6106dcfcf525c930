// StopSignals (common/app): a SIGTERM or SIGINT from another thread or process ends the
// wait, a duration ends it with 0, and Requested() never blocks.
#include <signal.h>
#include <sys/select.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "app/stop_signals.h"

namespace snapthread::app {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

TEST(StopSignalsTest, DurationEndsTheWaitWithZero) {
  StopSignals stop;
  const auto start = Clock::now();
  EXPECT_EQ(stop.Wait(0.2), 0);
  const double s = SecondsSince(start);
  EXPECT_GE(s, 0.19);
  EXPECT_LT(s, 2.0);
  EXPECT_FALSE(stop.Requested());
  EXPECT_EQ(stop.received(), 0);
}

TEST(StopSignalsTest, SigtermFromAnotherThreadEndsTheWait) {
  StopSignals stop;  // before the thread: it inherits the mask
  std::thread sender([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    ::kill(::getpid(), SIGTERM);  // to the process, as `kill` does
  });
  const auto start = Clock::now();
  EXPECT_EQ(stop.Wait(0.0), SIGTERM);  // no duration: only the signal ends it
  EXPECT_LT(SecondsSince(start), 5.0);
  sender.join();
  EXPECT_TRUE(stop.Requested());  // stays requested
  EXPECT_EQ(stop.Wait(10.0), SIGTERM);  // and a later wait returns at once
}

TEST(StopSignalsTest, SigintBeforeTheDurationEnds) {
  StopSignals stop;
  ::kill(::getpid(), SIGINT);
  const auto start = Clock::now();
  EXPECT_EQ(stop.Wait(30.0), SIGINT);
  EXPECT_LT(SecondsSince(start), 1.0);
}

TEST(StopSignalsTest, RequestedPollsWithoutBlocking) {
  StopSignals stop;
  const auto start = Clock::now();
  EXPECT_FALSE(stop.Requested());
  EXPECT_LT(SecondsSince(start), 0.5);
  ::kill(::getpid(), SIGTERM);
  EXPECT_TRUE(stop.Requested());
  EXPECT_EQ(stop.received(), SIGTERM);
}

TEST(StopSignalsTest, SignalFdBecomesReadable) {
  StopSignals stop;
  const int fd = stop.OpenFd();
  ASSERT_GE(fd, 0);
  ::kill(::getpid(), SIGTERM);
  fd_set readable;
  FD_ZERO(&readable);
  FD_SET(fd, &readable);
  timeval timeout{2, 0};
  EXPECT_EQ(::select(fd + 1, &readable, nullptr, nullptr, &timeout), 1);
  EXPECT_TRUE(stop.Requested());  // the signal is still there to take
  ::close(fd);
}

}  // namespace
}  // namespace snapthread::app
