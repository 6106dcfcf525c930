// A host without the session key flooding a snapthread session: forged messages on every
// channel of the session (<S>_DEVICE_STATE, _FORCE_MODEL, _SHAPE, _SOLVER_STATUS,
// _DEVICE_STATUS, _COMMAND) at a fixed rate per channel, from one thread. Each is a valid
// LCM encoding of its channel's type that passes the receivers' decode and validation, so
// it costs them the whole receive path up to the MAC check, and carries a MAC made under
// a key of the forger's own (docs/security.md, "Denial of service"). The forged force
// models ask for `forged_force_n` newtons along +z with a stiff K: a device that rendered
// one would push along z, which a planar scene never does.
//
// Used by the flood chart of snapthread-bench (flood.cc) and the attack test
// tests/attack/flood_test.cc.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

namespace snapthread::flood {

struct ForgerOptions {
  std::string lcm_url;
  std::string session;  // the genuine session whose channels are flooded
  double rate_per_channel_hz = 10000.0;
  // What the forged messages carry: a force model asking for this many newtons along +z,
  // and shapes of this many nodes.
  double forged_force_n = 1000.0;
  int forged_shape_nodes = 20;
  // Forged epoch and auth_seq: anything; the MAC check comes first and refuses them.
  int64_t epoch = 0x5eed;
};

class ForgedFlood {
 public:
  explicit ForgedFlood(ForgerOptions options);
  ~ForgedFlood();  // Stop()
  ForgedFlood(const ForgedFlood&) = delete;
  ForgedFlood& operator=(const ForgedFlood&) = delete;

  // Starts the flooding thread; false with *error when LCM cannot start or a message
  // cannot be built.
  bool Start(std::string* error);
  // Stops and joins the thread (idempotent).
  void Stop();

  static constexpr int kChannels = 6;
  // Messages handed to LCM so far, on all channels together, and publish failures.
  uint64_t sent() const { return sent_.load(std::memory_order_relaxed); }
  uint64_t failures() const { return failures_.load(std::memory_order_relaxed); }
  // Achieved messages per second per channel between Start and Stop (or now).
  double AchievedRatePerChannel() const;

 private:
  void Run();

  ForgerOptions options_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> sent_{0}, failures_{0};
  std::atomic<int64_t> start_ns_{0}, stop_ns_{0};
  struct Prepared;
  std::unique_ptr<Prepared> prepared_;
};

}  // namespace snapthread::flood
