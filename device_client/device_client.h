// DeviceClient: the device side of a session, given an open HapticDevice and a
// DeviceTransport (LCM in production, in memory in the tests). It owns the safety layer,
// the servo tick and loop, the model receiver and the hand-over rings; set-up (the
// constructor) is apart from the loop. Three steps, each one a method a test can call
// without threads, and each run by its own thread in production (Start):
//   servo    Tick: read the device, take the latest model, safety, command, rings.
//            No allocation, logging, blocking lock or transport call (ServoTick).
//   receive  Receive: force models from the transport -> ModelReceiver -> LatestValue.
//   io       Service: poses -> device_state_t, trace CSV rows, lateness statistics and
//            a device_status_t every status_period_us (built, then sent).
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "auth/pose_echo_window.h"
#include "auth/session_epoch.h"
#include "device_keys.h"
#include "haptic_device.h"
#include "messages/channels.h"
#include "model_receiver.h"
#include "realtime/percentiles.h"
#include "safety.h"
#include "servo_loop.h"
#include "sim_clock.h"
#include "snapthread/device_state_t.hpp"
#include "snapthread/device_status_t.hpp"
#include "transport.h"

namespace snapthread::device {

struct DeviceClientConfig {
  std::string device_id = "device";  // device_state_t.device_id, e.g. "virtual-hand"
  // The scene grasp this device holds (device_state_t.grasp; "" = the scene's
  // only grasp): force models for another grasp are not for this device.
  std::string grasp;
  SafetyLimits limits;               // must be valid (SafetyLimits::IsValid)
  bool device_has_orientation = false;  // DeviceCapabilities::has_orientation
  bool device_torque_output = false;    // DeviceCapabilities::has_torque_output
  ServoTickOptions tick;
  ServoLoopOptions loop;
  std::string trace_file;            // per-tick CSV, empty = none
  int64_t status_period_us = 500000; // DEVICE_STATUS at 2 Hz
  int64_t log_period_us = 5000000;   // a summary line every 5 s (0 = never)
  int receive_wait_ms = 20;          // receive thread: longest wait per poll
  MicrosClock clock = nullptr;       // CLOCK_MONOTONIC when null; tests use a fake clock
  // The device's credential (must outlive the client): poses are MACed and statuses
  // MACed and signed with it, force models and solver statuses checked (docs/security.md,
  // "Roles on the wire"); a reload (DeviceKeys::Replace, any thread) takes effect from the
  // next pose. snapthread-device always sets it; nullptr (no authentication) is for
  // in-process tests of other concerns.
  const DeviceKeys* keys = nullptr;
  std::string session = messages::kDefaultSession;  // channel prefix (for the MACs)
  // Snap-ahead (snap_ahead.h): switch to a fold's post-snap model at the tick the hand
  // crosses its boundary. --no-snap-ahead turns it off.
  bool snap_ahead = true;
};

// Statistics of the run so far (the --summary JSON and the last log line).
struct DeviceClientSummary {
  double duration_s = 0.0;
  uint64_t ticks = 0;
  double tick_rate_hz = 0.0;
  realtime::PercentileSummary lateness_us;
  double lateness_us_max = 0.0;
  realtime::PercentileSummary round_trip_us;
  uint64_t models_received = 0, models_rejected = 0, invalid_models = 0;
  uint64_t poses_rejected = 0, force_clamps = 0, stiffness_clamps = 0, slew_limits = 0;
  uint64_t fade_ticks = 0, snaps_felt = 0, nonfinite_outputs = 0, overruns = 0;
  uint64_t torque_clamps = 0, torque_slew_limits = 0;  // torque-output devices only
  uint64_t wrench_models = 0;  // accepted 6-DoF models (has_wrench)
  uint64_t snap_ahead_switches = 0;
  // Solver statuses authenticated / refused (the device learns the epoch from them); the
  // transport's unchecked ones replaced before they were checked and those dropped for
  // their size (set by the caller that owns the transport: snapthread-device).
  uint64_t statuses_accepted = 0, statuses_rejected = 0;
  uint64_t statuses_superseded = 0, statuses_oversized = 0;
  uint64_t read_failures = 0, pose_ring_drops = 0, trace_ring_drops = 0;
  uint64_t invalid_poses_unpublished = 0, publish_failures = 0, poses_published = 0;
  double max_force_n = 0.0;
  double final_force_n = 0.0;  // |F| commanded at the last servo tick before Stop
  bool realtime = false;
};

class DeviceClient {
 public:
  // device (open) and transport must outlive the client. Throws std::invalid_argument
  // for invalid limits and std::runtime_error naming the file when the trace cannot be
  // written (start-up errors).
  DeviceClient(HapticDevice* device, DeviceTransport* transport, DeviceClientConfig config);
  ~DeviceClient();
  DeviceClient(const DeviceClient&) = delete;
  DeviceClient& operator=(const DeviceClient&) = delete;

  // Production: starts the servo loop and the receive and io threads. *notes gets one
  // line per real-time feature that could not be enabled.
  void Start(std::string* notes);
  // Fades the force to zero through the safety ramp (fade_time_s) while the servo loop
  // runs; waits up to timeout_s for the last commanded |F| to reach 0 (true when it did).
  // Call before Stop on a signal.
  bool FadeOut(double timeout_s);
  // Stops the threads, commands zero force, flushes the rings and the trace. Idempotent.
  void Stop();

  // The steps the threads run; tests call them directly (one thread each at most).
  void Tick(int64_t now_us, int64_t lateness_us);
  int Receive(int wait_ms);
  void Service(int64_t now_us);

  // Builds this instant's DEVICE_STATUS (tick rate over the last status period); the
  // io thread sends it. Reads io-thread state: call from the io thread.
  device_status_t BuildStatus(int64_t now_us, double tick_rate_hz, int64_t seq) const;
  // The run so far (all of it after Stop). Reads io-thread state: call after Stop, or
  // from the thread that calls Service.
  DeviceClientSummary Summary(int64_t now_us) const;

  const ModelReceiver& receiver() const { return receiver_; }
  const ForceSafety& safety() const { return safety_; }
  const ServoTick& servo() const { return tick_; }
  bool realtime_active() const { return loop_.realtime_active(); }
  int64_t start_us() const { return start_us_; }

 private:
  int64_t Now() const;
  void Drain();
  // io thread: tag state_msg_ / a status with the current credential (no-ops without
  // one); false when it cannot be tagged (then it is not sent).
  bool SignPose();
  bool SignStatus(device_status_t* st);
  void MaybeReport(int64_t now_us);

  HapticDevice* device_;
  DeviceTransport* transport_;
  DeviceClientConfig config_;
  ForceSafety safety_;
  std::unique_ptr<ModelSlot> models_;
  std::unique_ptr<PoseRing> poses_;
  std::unique_ptr<TraceRing> trace_ring_;
  std::unique_ptr<LatenessRing> lateness_;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> trace_file_;
  messages::Channels channels_;
  std::unique_ptr<auth::PoseEchoWindow> sent_poses_;  // written by the io thread
  ModelReceiver receiver_;
  SnapAhead snap_ahead_;  // servo thread (via tick_)
  ServoTick tick_;
  ServoLoop loop_;

  // io-thread state.
  auth::AuthSequence auth_seq_;
  device_state_t state_msg_{};
  realtime::SampleWindow lateness_window_{1000};  // last second, for DEVICE_STATUS
  realtime::SampleWindow lateness_run_{600000};   // last 10 min at 1 kHz, for the summary
  double lateness_max_us_ = 0.0;
  int64_t last_status_us_ = 0;
  int64_t last_log_us_ = 0;
  uint64_t last_status_ticks_ = 0;
  int64_t status_seq_ = 0;
  std::atomic<uint64_t> invalid_poses_unpublished_{0};
  std::atomic<uint64_t> publish_failures_{0};
  std::atomic<uint64_t> poses_published_{0};

  int64_t start_us_ = 0;
  int64_t end_us_ = -1;
  std::atomic<bool> stop_threads_{false};
  std::thread receive_thread_;
  std::thread io_thread_;
  bool started_ = false;
  double final_force_n_ = 0.0;  // |F| at the last tick, kept by Stop
};

}  // namespace snapthread::device
