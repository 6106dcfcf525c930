// The servo watchdog in a real snapthread-device process: the simulated device's render
// thread (its "firmware", --sim-render-file) publishes what it renders in a shared file;
// this test stops only the device's servo thread (ptrace: PTRACE_SEIZE + PTRACE_INTERRUPT
// on that one thread, as a debugger or a stalled real-time thread would leave it), while
// the process's other threads, the render thread included, run on. Within 10 ms of the
// last command the rendered force must be zero, and stay zero while the servo is stopped;
// released, the servo renders the spring again. A SIGSTOP of the whole process would stop
// the simulated device too, so it would test nothing; a real device's controller
// (dhdSetWatchdog) or scheduler callback (OpenHaptics) is what covers that case.
#include <gtest/gtest.h>

#include <dirent.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/ptrace.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "device_fake_server.h"
#include "realtime/clock.h"
#include "sim_renderer.h"
#include "test_support.h"

namespace snapthread::device {
namespace {

using testing::DeviceProcess;
using testing::FakeServer;
using testing::WriteDeviceScene;

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The pid of the process whose command line holds `marker` and `program` (-1: none).
pid_t FindProcess(const std::string& program, const std::string& marker) {
  DIR* proc = opendir("/proc");
  if (proc == nullptr) return -1;
  pid_t found = -1;
  while (dirent* e = readdir(proc)) {
    const pid_t pid = static_cast<pid_t>(std::atoi(e->d_name));
    if (pid <= 0) continue;
    std::string cmd = Slurp("/proc/" + std::string(e->d_name) + "/cmdline");
    std::replace(cmd.begin(), cmd.end(), '\0', ' ');
    if (cmd.find(program) != std::string::npos && cmd.find(marker) != std::string::npos) {
      found = pid;
      break;
    }
  }
  closedir(proc);
  return found;
}

// The thread of `pid` named `name` (pthread_setname_np; -1: none).
pid_t FindThread(pid_t pid, const std::string& name) {
  const std::string dir = "/proc/" + std::to_string(pid) + "/task";
  DIR* tasks = opendir(dir.c_str());
  if (tasks == nullptr) return -1;
  pid_t found = -1;
  while (dirent* e = readdir(tasks)) {
    const pid_t tid = static_cast<pid_t>(std::atoi(e->d_name));
    if (tid <= 0) continue;
    std::string comm = Slurp(dir + "/" + e->d_name + "/comm");
    while (!comm.empty() && comm.back() == '\n') comm.pop_back();
    if (comm == name) found = tid;
  }
  closedir(tasks);
  return found;
}

double Norm(const double f[3]) { return std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]); }

TEST(DeviceWatchdogProcessTest, StoppedServoThreadZeroesTheRenderedForceWithin10Ms) {
  const test_support::SessionKeyFile key_file;
  const test_support::ScopedTempDir scoped("device_watchdog");
  const std::string& dir = scoped.path();
  const std::string session = test_support::UniqueSession("DEVWD");
  const std::string render_file = dir + "/render";
  FakeServer server(session, &key_file.key());
  ASSERT_TRUE(server.good()) << "udpm on loopback unavailable";
  const std::string bin = test_support::BinDir() + "/snapthread-device";
  const std::string scene = WriteDeviceScene(dir, "device_watchdog_process_test");
  DeviceProcess device({bin, "--backend", "sim-path", "--scene", scene, "--session", session,
                        "--lcm-url", test_support::kLoopbackLcmUrl, "--duration", "8",
                        "--speed-m-per-s", "0.04", "--no-rt", "--log-level", "warn",
                        "--sim-render-file", render_file, "--summary", dir + "/summary.json"},
                       dir + "/device");
  ASSERT_TRUE(device.started());
  ASSERT_TRUE(test_support::WaitForFile(render_file, 10.0 * test_support::SpeedScale()))
      << Slurp(dir + "/device.err");
  const int fd = open(render_file.c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  void* map = mmap(nullptr, sizeof(RenderedOutput), PROT_READ, MAP_SHARED, fd, 0);
  close(fd);
  ASSERT_NE(map, MAP_FAILED);
  const auto* record = static_cast<const RenderedOutput*>(map);

  const pid_t pid = FindProcess(bin, session);
  ASSERT_GT(pid, 0);
  pid_t servo = -1;
  ASSERT_TRUE(test_support::WaitUntil([&] { return (servo = FindThread(pid, "servo")) > 0; }, 5.0));

  std::vector<double> latencies_ms;
  RenderedSample s;
  for (int round = 0; round < 5; ++round) {
    // The spring is felt: the render thread renders a force.
    ASSERT_TRUE(test_support::WaitUntil(
        [&] { return ReadRendered(*record, &s) && Norm(s.force_n) > 0.05; },
        5.0 * test_support::SpeedScale(), 0.001))
        << "round " << round << ": no force rendered\n" << Slurp(dir + "/device.err");

    // Stop the servo thread alone.
    ASSERT_EQ(ptrace(PTRACE_SEIZE, servo, nullptr, nullptr), 0) << std::strerror(errno);
    ASSERT_EQ(ptrace(PTRACE_INTERRUPT, servo, nullptr, nullptr), 0) << std::strerror(errno);
    int status = 0;
    ASSERT_EQ(waitpid(servo, &status, __WALL), servo);
    ASSERT_TRUE(WIFSTOPPED(status));
    const int64_t stopped_us = realtime::MonotonicMicros();
    // Watch the render thread's output for 100 ms while the servo stays stopped.
    bool late_force = false;
    const int64_t watch_end = realtime::MonotonicMicros() + 100000;
    uint64_t renders_at_start = 0;
    while (realtime::MonotonicMicros() < watch_end) {
      if (ReadRendered(*record, &s)) {
        if (renders_at_start == 0) renders_at_start = s.renders;
        // Any render more than 10 ms after the last command must be zero.
        if (s.t_us > s.command_us + 10000 && !s.IsZero()) late_force = true;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    ASSERT_TRUE(ReadRendered(*record, &s));
    EXPECT_FALSE(late_force) << "round " << round;
    EXPECT_LE(s.command_us, stopped_us) << "round " << round << ": the servo kept commanding";
    EXPECT_TRUE(s.IsZero()) << "round " << round << ": " << Norm(s.force_n) << " N";
    EXPECT_GT(s.renders, renders_at_start + 50) << "round " << round << ": the render thread stalled";
    ASSERT_NE(s.zero_since_us, INT64_MIN);
    const double latency_ms = 1e-3 * static_cast<double>(s.zero_since_us - s.command_us);
    EXPECT_LE(latency_ms, 10.0) << "round " << round;
    latencies_ms.push_back(latency_ms);

    ASSERT_EQ(ptrace(PTRACE_DETACH, servo, nullptr, nullptr), 0) << std::strerror(errno);
  }
  // Released, the servo commands again and the spring is rendered again.
  EXPECT_TRUE(test_support::WaitUntil(
      [&] { return ReadRendered(*record, &s) && Norm(s.force_n) > 0.05; },
      5.0 * test_support::SpeedScale(), 0.001));
  munmap(map, sizeof(RenderedOutput));
  EXPECT_EQ(device.ExitCode(30.0 * test_support::SpeedScale()), 0) << Slurp(dir + "/device.err");
  std::sort(latencies_ms.begin(), latencies_ms.end());
  std::printf("servo thread stopped by ptrace: rendered force zero %.2f ms (median), %.2f ms (max) "
              "after the last command, %zu stops\n",
              latencies_ms[latencies_ms.size() / 2], latencies_ms.back(), latencies_ms.size());
}

}  // namespace
}  // namespace snapthread::device
