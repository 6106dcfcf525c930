// The hand-over from the receive thread to the solve thread: the newest device pose of
// each grasp of each sender (device_state_t.grasp and sender_name, so one device cannot
// displace another's pose; latest wins: a pose that arrives before the solver
// took the previous one of its grasp replaces it, so the solver never works through a
// queue of stale poses) and a short FIFO of commands (commands are rare and must not be
// lost). One mutex and one condition variable; the receive thread is not real-time, so
// blocking for a few microseconds is fine there. Only authenticated messages enter it
// (the inbound gate, inbound_gate.h, puts a pose or command here after its MAC and
// freshness passed), so a grasp slot is never made from a forged name and nothing
// unchecked can take the place of a genuine message.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <vector>

#include "snapthread/command_t.hpp"
#include "snapthread/device_state_t.hpp"

namespace snapthread::server {

struct DeviceKey;  // server_keys.h

// A validated pose, when it arrived and the device key it was made with (kept by the
// gate's ServerKeys for the server's life: the force model answering it is MACed with it).
struct ReceivedPose {
  device_state_t state;
  int64_t receive_utime = 0;  // server CLOCK_REALTIME, microseconds
  const DeviceKey* key = nullptr;
};

class ServerInbox {
 public:
  using Clock = std::chrono::steady_clock;
  // Commands beyond this many unprocessed ones are refused (a flood, not a user).
  static constexpr size_t kMaxPendingCommands = 64;
  // Grasps with a pending pose at once; a pose for a further grasp name is dropped (and
  // reported as superseded) until the solver took the others.
  static constexpr size_t kMaxGrasps = 8;

  // Stores the pose as the newest of its grasp. True when it superseded a pose nobody
  // took, or was dropped (kMaxGrasps) (the caller counts it as a dropped pose).
  bool PutPose(const ReceivedPose& pose);
  // Queues a command. False when the queue is full (the command is refused).
  bool PushCommand(const command_t& command);
  // Wakes the solve thread for good.
  void RequestStop();

  struct Taken {
    bool stop = false;
    std::vector<ReceivedPose> poses;  // the newest of each grasp, in order of arrival
    std::vector<command_t> commands;
  };
  // Blocks until a pose or command is pending, stop was requested, or `deadline`;
  // takes everything pending.
  Taken Wait(Clock::time_point deadline);

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<ReceivedPose> poses_;
  std::deque<command_t> commands_;
  bool stop_ = false;
};

}  // namespace snapthread::server
