#include "app/stop_signals.h"

#include <pthread.h>
#include <sys/signalfd.h>

#include <algorithm>
#include <cerrno>
#include <ctime>

namespace snapthread::app {
namespace {

double MonotonicSeconds() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

// One sigtimedwait of at most `wait_s` seconds: the signal, or 0 (timeout, EINTR).
int WaitOnce(const sigset_t& signals, double wait_s) {
  timespec timeout{};
  timeout.tv_sec = static_cast<time_t>(wait_s);
  timeout.tv_nsec = static_cast<long>((wait_s - static_cast<double>(timeout.tv_sec)) * 1e9);
  const int sig = sigtimedwait(&signals, nullptr, &timeout);
  return sig > 0 ? sig : 0;
}

}  // namespace

StopSignals::StopSignals() {
  sigemptyset(&signals_);
  sigaddset(&signals_, SIGINT);
  sigaddset(&signals_, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals_, nullptr);
}

int StopSignals::Wait(double duration_s) {
  if (received_ != 0) return received_;
  // Waits in slices of at most 1 s: a wait cut short (EINTR from a debugger, a clock
  // step) only costs a new slice, and the duration is measured on the monotonic clock.
  constexpr double kSliceS = 1.0;
  const double end = MonotonicSeconds() + duration_s;
  while (true) {
    double wait_s = kSliceS;
    if (duration_s > 0.0) {
      const double left = end - MonotonicSeconds();
      if (left <= 0.0) return 0;
      wait_s = std::min(wait_s, left);
    }
    if (const int sig = WaitOnce(signals_, wait_s); sig != 0) {
      received_ = sig;
      return sig;
    }
  }
}

bool StopSignals::Requested() {
  if (received_ == 0) received_ = WaitOnce(signals_, 0.0);
  return received_ != 0;
}

int StopSignals::OpenFd() const { return signalfd(-1, &signals_, SFD_CLOEXEC); }

}  // namespace snapthread::app
