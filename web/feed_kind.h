// What the bridge sends a page, one kind per WebSocket message "type": the four session
// channels, the bridge's own counters, the replay position and the answer to a ping.
#pragma once

#include <cstdint>

namespace snapthread::web {

enum class FeedKind : uint8_t {
  kShape = 0,       // thread_shape_t        "shape"
  kForceModel,      // force_model_t         "force"
  kSolverStatus,    // solver_status_t       "solver"
  kDeviceStatus,    // device_status_t       "device"
  kBridge,          // bridge counters       "bridge"
  kReplay,          // replay position       "replay"
  kPong,            // answer to a page ping "pong"
};
inline constexpr int kFeedKinds = 7;

inline constexpr int Index(FeedKind kind) { return static_cast<int>(kind); }

}  // namespace snapthread::web
