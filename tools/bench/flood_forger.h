// A forger flooding a snapthread session: forged messages on every channel of the session
// (<S>_DEVICE_STATE, _FORCE_MODEL, _SHAPE, _SOLVER_STATUS, _DEVICE_STATUS, _COMMAND) at a
// fixed rate per channel, from one thread. Each is a valid LCM encoding of its channel's
// type that passes the receivers' decode and validation, so it costs them the whole
// receive path up to the tag check (docs/security.md, "Denial of service"). What the tags
// are made with is the forger's kind (ForgerKind): no key of the session, or a credential
// of a role that may not speak there, or another session's root key. The forged force
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

// What the forger holds, and so how it tags (docs/security.md, "Roles on the wire").
enum class ForgerKind {
  // No key of the session: MACs under a key of its own, claiming each channel's sender.
  kNoKey,
  // This session's observer credential: MACs with the one secret it holds (the read key),
  // claiming each channel's sender.
  kObserver,
  // Another device's credential (`forger_name`): its own key, MACs that verify. Its poses
  // claim its own name (a grasp it does not hold); elsewhere it claims the genuine senders.
  // It sends no DEVICE_STATUS (a device may report its own status).
  kOtherDevice,
  // An operator credential (`forger_name`): its own key and role on every channel but
  // COMMAND (where an operator may speak).
  kOperator,
  // Another session's root key: signs as that session's server and MACs with that
  // session's device "hand" and operator keys, claiming each channel's sender.
  kOtherSessionRoot,
};
const char* ForgerKindName(ForgerKind kind);

struct ForgerOptions {
  std::string lcm_url;
  std::string session;  // the genuine session whose channels are flooded
  double rate_per_channel_hz = 10000.0;
  // What the forged messages carry: a force model asking for this many newtons along +z,
  // and shapes of this many nodes.
  double forged_force_n = 1000.0;
  int forged_shape_nodes = 20;
  // Forged epoch and auth_seq: anything; the tag check comes first and refuses them.
  // Forgers holding one of this session's credentials first learn the genuine epoch from
  // a SOLVER_STATUS signed by the server (up to `learn_epoch_s`), so that only their role
  // can stop them; `epoch` is kept when none comes.
  int64_t epoch = 0x5eed;
  double learn_epoch_s = 5.0;
  ForgerKind kind = ForgerKind::kNoKey;
  // This session's root key file: kObserver, kOtherDevice and kOperator issue their
  // credential from it (as snapthread-keygen would on the server host).
  std::string root_key_path;
  std::string forger_name = "intruder";  // the credential's name (kOtherDevice, kOperator)
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

  // Channels flooded: 6, or 5 where the kind may speak on one (see ForgerKind).
  int channels() const { return channels_; }
  // Messages handed to LCM so far, on all channels together, and publish failures.
  uint64_t sent() const { return sent_.load(std::memory_order_relaxed); }
  uint64_t failures() const { return failures_.load(std::memory_order_relaxed); }
  // Achieved messages per second per channel between Start and Stop (or now).
  double AchievedRatePerChannel() const;

 private:
  void Run();
  int channels_ = 6;

  ForgerOptions options_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> sent_{0}, failures_{0};
  std::atomic<int64_t> start_ns_{0}, stop_ns_{0};
  struct Prepared;
  std::unique_ptr<Prepared> prepared_;
};

}  // namespace snapthread::flood
