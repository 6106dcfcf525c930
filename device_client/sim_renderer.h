// SimRenderer: the "firmware" of a simulated backend. A thread of its own, apart from the
// servo loop, renders the backend's StaleCommand every millisecond as a real device's
// controller would, and publishes what it rendered in a RenderedOutput record: in memory,
// or in a memory-mapped file another process (a test) can watch. It makes the stale-command
// watchdog observable: stop the servo thread (or stop commanding) and the rendered output
// goes to zero within the command's age limit plus one render period.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include "sim_clock.h"
#include "stale_command.h"

namespace snapthread::device {

// The published record (a sequence lock over atomics, address-free, so it may live in a
// MAP_SHARED file). Written by the render thread only.
struct RenderedOutput {
  static constexpr uint64_t kMagic = 0x534e41505244ull;  // "SNAPRD"
  std::atomic<uint64_t> magic{0};
  std::atomic<uint64_t> seq{0};               // odd while a sample is being written
  std::atomic<int64_t> t_us{0};               // CLOCK_MONOTONIC of this render
  std::atomic<int64_t> command_us{INT64_MIN}; // stamp of the last command seen then
  std::atomic<double> force_n[3] = {0.0, 0.0, 0.0};
  std::atomic<double> torque_nm[3] = {0.0, 0.0, 0.0};
  // Render time of the first zero output of the current run of zeros (INT64_MIN while the
  // output is not zero): zero_since_us - command_us is how long the last command lasted.
  std::atomic<int64_t> zero_since_us{INT64_MIN};
  std::atomic<uint64_t> renders{0};
};

// A consistent copy of a RenderedOutput.
struct RenderedSample {
  int64_t t_us = 0;
  int64_t command_us = INT64_MIN;
  double force_n[3] = {0.0, 0.0, 0.0};
  double torque_nm[3] = {0.0, 0.0, 0.0};
  int64_t zero_since_us = INT64_MIN;
  uint64_t renders = 0;
  bool IsZero() const;
};

// Reads *record consistently (any thread or process); false when no consistent read came
// within a few attempts or the record was never written.
bool ReadRendered(const RenderedOutput& record, RenderedSample* out);

class SimRenderer {
 public:
  static constexpr int64_t kPeriodUs = 1000;

  // command must outlive the renderer; clock gives the render times (CLOCK_MONOTONIC in
  // production).
  SimRenderer(const StaleCommand* command, MicrosClock clock);
  ~SimRenderer();
  SimRenderer(const SimRenderer&) = delete;
  SimRenderer& operator=(const SimRenderer&) = delete;

  // Starts the render thread (SCHED_FIFO above the servo when permitted). With a file,
  // the record is created there (mode 0600, replaced if it exists) and shared. False
  // with *error when the file cannot be made.
  bool Start(const std::string& shared_file, std::string* error);
  void Stop();
  // One render at now_us (the thread's step; tests without a thread call it directly).
  void RenderOnce(int64_t now_us);

  const RenderedOutput& record() const { return *record_; }

 private:
  void Run();

  const StaleCommand* command_;
  MicrosClock clock_;
  RenderedOutput local_;
  RenderedOutput* record_ = &local_;
  void* mapping_ = nullptr;
  std::thread thread_;
  std::atomic<bool> stop_{false};
};

}  // namespace snapthread::device
