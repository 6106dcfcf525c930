#include "sim_renderer.h"

#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <new>

namespace snapthread::device {

bool RenderedSample::IsZero() const {
  for (int k = 0; k < 3; ++k) {
    if (force_n[k] != 0.0 || torque_nm[k] != 0.0) return false;
  }
  return true;
}

bool ReadRendered(const RenderedOutput& r, RenderedSample* out) {
  if (r.magic.load(std::memory_order_acquire) != RenderedOutput::kMagic) return false;
  for (int attempt = 0; attempt < 64; ++attempt) {
    const uint64_t s0 = r.seq.load(std::memory_order_acquire);
    if ((s0 & 1u) != 0) continue;
    out->t_us = r.t_us.load(std::memory_order_relaxed);
    out->command_us = r.command_us.load(std::memory_order_relaxed);
    for (int k = 0; k < 3; ++k) {
      out->force_n[k] = r.force_n[k].load(std::memory_order_relaxed);
      out->torque_nm[k] = r.torque_nm[k].load(std::memory_order_relaxed);
    }
    out->zero_since_us = r.zero_since_us.load(std::memory_order_relaxed);
    out->renders = r.renders.load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (r.seq.load(std::memory_order_relaxed) == s0) return true;
  }
  return false;
}

SimRenderer::SimRenderer(const StaleCommand* command, MicrosClock clock)
    : command_(command), clock_(clock) {
  local_.magic.store(RenderedOutput::kMagic, std::memory_order_release);
}

SimRenderer::~SimRenderer() {
  Stop();
  if (mapping_ != nullptr) munmap(mapping_, sizeof(RenderedOutput));
}

bool SimRenderer::Start(const std::string& shared_file, std::string* error) {
  if (thread_.joinable()) return true;
  if (!shared_file.empty() && mapping_ == nullptr) {
    const std::string tmp = shared_file + ".tmp";
    const int fd = open(tmp.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0600);
    if (fd < 0 || ftruncate(fd, sizeof(RenderedOutput)) != 0) {
      if (error) *error = "cannot create " + tmp + ": " + std::strerror(errno);
      if (fd >= 0) close(fd);
      return false;
    }
    void* p = mmap(nullptr, sizeof(RenderedOutput), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    close(fd);
    if (p == MAP_FAILED) {
      if (error) *error = "cannot map " + tmp + ": " + std::strerror(errno);
      return false;
    }
    mapping_ = p;
    record_ = new (p) RenderedOutput();
    record_->magic.store(RenderedOutput::kMagic, std::memory_order_release);
    // Renamed into place once initialised: a watcher never maps a half-made record.
    if (rename(tmp.c_str(), shared_file.c_str()) != 0) {
      if (error) *error = "cannot rename " + tmp + ": " + std::strerror(errno);
      return false;
    }
  }
  stop_.store(false);
  thread_ = std::thread(&SimRenderer::Run, this);
  // Above the servo loop's priority (80), as a device's controller is: it must render
  // (zero) even when the servo thread spins. Ignored when not permitted.
  sched_param sp{};
  sp.sched_priority = 81;
  pthread_setschedparam(thread_.native_handle(), SCHED_FIFO, &sp);
  pthread_setname_np(thread_.native_handle(), "sim-render");
  return true;
}

void SimRenderer::Stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void SimRenderer::RenderOnce(int64_t now_us) {
  double f[3], t[3];
  command_->Output(now_us, f, t);
  RenderedOutput& r = *record_;
  bool zero = true;
  for (int k = 0; k < 3; ++k) zero = zero && f[k] == 0.0 && t[k] == 0.0;
  const uint64_t s = r.seq.load(std::memory_order_relaxed);
  r.seq.store(s + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  r.t_us.store(now_us, std::memory_order_relaxed);
  r.command_us.store(command_->last_command_us(), std::memory_order_relaxed);
  for (int k = 0; k < 3; ++k) {
    r.force_n[k].store(f[k], std::memory_order_relaxed);
    r.torque_nm[k].store(t[k], std::memory_order_relaxed);
  }
  if (!zero) {
    r.zero_since_us.store(INT64_MIN, std::memory_order_relaxed);
  } else if (r.zero_since_us.load(std::memory_order_relaxed) == INT64_MIN) {
    r.zero_since_us.store(now_us, std::memory_order_relaxed);
  }
  r.renders.store(r.renders.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  r.seq.store(s + 2, std::memory_order_release);
}

void SimRenderer::Run() {
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  while (!stop_.load(std::memory_order_relaxed)) {
    next.tv_nsec += kPeriodUs * 1000;
    while (next.tv_nsec >= 1000000000L) {
      next.tv_nsec -= 1000000000L;
      ++next.tv_sec;
    }
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr) == EINTR) {
    }
    RenderOnce(clock_());
    // Behind by more than a period (descheduled): re-anchor rather than burst.
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    if ((now.tv_sec - next.tv_sec) * 1000000000L + (now.tv_nsec - next.tv_nsec) > kPeriodUs * 1000) {
      next = now;
    }
  }
}

}  // namespace snapthread::device
