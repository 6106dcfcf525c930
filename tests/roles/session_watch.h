// An observer of a role test's session, in the test process: it checks what arrives as an
// observer holding only the server's public key does (auth::VerifySignature; a device's
// status by the server's certificate of the device's key, then that key's signature) and
// keeps what the tests assert on: the latest verified solver status (scene, counters,
// refusals), the latest verified status of each device, and how many messages carrying a
// forger's marker ("FORGED") it heard and how many of those verified (must stay 0).
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "auth/key_id.h"
#include "lcm_thread.h"
#include "messages/channels.h"

namespace snapthread::roles_test {

// What forgers write into the messages they make, so an observer can tell them apart.
inline constexpr const char* kForgedMarker = "FORGED";

// "role/reason=count ..." (solver_status_t.refusals) as a map; Refusals(text, "device")
// sums one role's reasons, Refusals(text, "device/revoked") is one count.
std::map<std::string, int64_t> ParseRefusals(const std::string& text);
int64_t Refusals(const std::string& text, const std::string& key);
int64_t TotalRefusals(const std::string& text);

struct SolverStatusView {
  std::string scene, method, refusals;
  int64_t updates = 0, dropped_poses = 0, rejected_messages = 0, epoch = 0;
  std::chrono::steady_clock::time_point at;
};

struct DeviceStatusView {
  int64_t models_received = 0, models_rejected = 0, fades = 0, ticks = 0;
  double force_norm_n = 0.0;
  std::chrono::steady_clock::time_point at;
};

// Counts of one channel as the observer saw them.
struct ChannelCounts {
  int64_t verified = 0;        // genuine: the signature (and certificate) checked
  int64_t refused = 0;         // decoded, signature did not check
  int64_t forged_heard = 0;    // carrying kForgedMarker
  int64_t forged_verified = 0; // carrying kForgedMarker and verified: a forgery accepted
};

class SessionWatch {
 public:
  SessionWatch(const std::string& session, const std::string& lcm_url,
               std::vector<auth::PublicKey> server_keys);
  ~SessionWatch();
  SessionWatch(const SessionWatch&) = delete;
  SessionWatch& operator=(const SessionWatch&) = delete;

  bool good() { return lcm_.lcm().good(); }
  // Also trust `key` from now on (a rotated server's new key).
  void AddServerKey(const auth::PublicKey& key);

  std::optional<SolverStatusView> status();
  std::optional<DeviceStatusView> device(const std::string& name);
  ChannelCounts shapes();
  ChannelCounts statuses();
  ChannelCounts device_statuses();
  // Every verified status of `name` so far, in arrival order.
  std::vector<DeviceStatusView> device_history(const std::string& name);

  // Waits up to timeout_s for a verified solver status / status of `name` that arrived
  // after this call; nullopt at the deadline.
  std::optional<SolverStatusView> NextStatus(double timeout_s);
  std::optional<DeviceStatusView> NextDevice(const std::string& name, double timeout_s);

 private:
  void OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void OnShape(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void OnDeviceStatus(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  bool VerifiedByServer(const lcm::ReceiveBuffer* rbuf, const std::string& channel);

  test_support::LcmThread lcm_;
  const messages::Channels channels_;
  std::mutex mutex_;
  std::vector<auth::PublicKey> server_keys_;
  std::optional<SolverStatusView> status_;
  std::map<std::string, std::vector<DeviceStatusView>> devices_;
  ChannelCounts shapes_, statuses_, device_statuses_;
};

}  // namespace snapthread::roles_test
