// The 1 kHz servo loop. ServoTick is one tick as a plain callable (read the device,
// take the latest force model, evaluate it through the safety layer, command the
// device, hand the pose and trace row to other threads); ServoLoop calls it on an
// absolute-deadline schedule from a dedicated (real-time when permitted) thread.
// Nothing on the servo thread allocates, logs, takes a blocking lock or calls LCM.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "haptic_device.h"
#include "safety.h"
#include "snap_ahead.h"
#include "realtime/latest_value.h"
#include "realtime/spsc_ring.h"

namespace snapthread::device {

// A pose for the publisher thread (becomes a device_state_t).
struct PoseToPublish {
  int64_t utime_us = 0;  // CLOCK_MONOTONIC at the read
  int64_t seq = 0;       // published pose number
  double position_m[3] = {0.0, 0.0, 0.0};
  double orientation[4] = {1.0, 0.0, 0.0, 0.0};
  int32_t buttons = 0;
  int64_t snap_fold_id = 0;  // the fold whose post-snap model the device switched to last
};

// One row of the --trace CSV.
struct TraceRow {
  int64_t utime_us = 0;
  int64_t tick = 0;
  double position_m[3] = {0.0, 0.0, 0.0};
  double force_n[3] = {0.0, 0.0, 0.0};
  double orientation[4] = {1.0, 0.0, 0.0, 0.0};  // (w, x, y, z) as read
  double torque_nm[3] = {0.0, 0.0, 0.0};         // commanded (0 without torque output)
  double model_age_ms = -1.0;
  int8_t model_status = -1;
  bool clamped = false;
  bool fading = false;
};

// Ring sizes: a few seconds of 1 kHz data, so a descheduled consumer loses nothing.
using PoseRing = realtime::SpscRing<PoseToPublish, 4096>;
using TraceRing = realtime::SpscRing<TraceRow, 8192>;
using LatenessRing = realtime::SpscRing<int32_t, 8192>;  // microseconds
using ModelSlot = realtime::LatestValue<LocalModel>;

struct ServoTickOptions {
  int publish_divisor = 1;  // hand every k-th pose to the publisher
  int trace_divisor = 1;    // every k-th tick to the trace (when a trace ring is given)
};

// Statistics written by the servo thread.
struct ServoCounters {
  std::atomic<uint64_t> ticks{0};
  std::atomic<uint64_t> read_failures{0};
  std::atomic<uint64_t> command_failures{0};
  std::atomic<double> force_norm_n{0.0};  // |F| commanded at the last tick
  std::atomic<int64_t> last_model_receive_us{-1};
};

class ServoTick {
 public:
  // Every pointer must outlive the tick. trace may be null (no trace).
  ServoTick(HapticDevice* device, ForceSafety* safety, ModelSlot* models, PoseRing* poses,
            TraceRing* trace, LatenessRing* lateness, ServoTickOptions options);

  // One tick at now_us (CLOCK_MONOTONIC), lateness_us after its deadline. Allocation-free.
  void Tick(int64_t now_us, int64_t lateness_us);
  // Snap-ahead (snap_ahead.h): each tick renders what it selects. Null (the default): off.
  void SetSnapAhead(SnapAhead* snap_ahead) { snap_ahead_ = snap_ahead; }

  const ServoCounters& counters() const { return counters_; }
  const SafetyOutput& last_output() const { return last_; }
  const DeviceState& last_state() const { return state_; }

 private:
  HapticDevice* device_;
  ForceSafety* safety_;
  ModelSlot* models_;
  PoseRing* poses_;
  TraceRing* trace_;
  LatenessRing* lateness_;
  SnapAhead* snap_ahead_ = nullptr;
  ServoTickOptions options_;
  ServoCounters counters_;
  DeviceState state_;
  SafetyOutput last_;
  int64_t tick_ = 0;
  int64_t pose_seq_ = 0;
};

struct ServoLoopOptions {
  double rate_hz = 1000.0;
  bool realtime = true;     // try SCHED_FIFO, mlockall and 1 ns timer slack
  int fifo_priority = 80;
};

class ServoLoop {
 public:
  ServoLoop(ServoTick* tick, ServoLoopOptions options);
  ~ServoLoop();
  ServoLoop(const ServoLoop&) = delete;
  ServoLoop& operator=(const ServoLoop&) = delete;

  // Starts the thread. *notes receives one line per real-time feature that could not be
  // enabled (empty when all were, or when realtime is off).
  void Start(std::string* notes);
  void Stop();

  bool realtime_active() const { return realtime_active_.load(); }
  // Deadlines missed by more than a whole period (the schedule was re-anchored).
  uint64_t overruns() const { return overruns_.load(std::memory_order_relaxed); }

 private:
  void Run();

  ServoTick* tick_;
  ServoLoopOptions options_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> realtime_active_{false};
  std::atomic<int> timer_slack_ok_{-1};  // set by the thread: 1 ok, 0 refused
  std::atomic<uint64_t> overruns_{0};
};

}  // namespace snapthread::device
