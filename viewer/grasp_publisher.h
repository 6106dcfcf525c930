// Mouse grasp mode: the viewer drives a session like a device would, publishing
// device_state_t on <SESSION>_DEVICE_STATE. Positions in the message are device metres, so the
// scene's DeviceMapping (device -> model) is inverted (messages::ModelPointToDevice).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

#include <Eigen/Core>
#include <lcm/lcm-cpp.hpp>

#include "auth/message_mac.h"
#include "auth/session_epoch.h"
#include "scene/scene.h"

namespace snapthread::viewer {

class GraspPublisher {
 public:
  // With a tagger (a device credential's, auth::KeySet::tagger(); it must outlive the
  // publisher) every pose is tagged as that device's, with the epoch `epoch()` returns (the
  // one the viewer learned from the server's status; 0 before: the server refuses those).
  // The server takes the poses only for the grasp the device's name is for.
  GraspPublisher(lcm::LCM* lcm, const std::string& session, const DeviceMapping& mapping,
                 const auth::Tagger* tagger = nullptr, std::function<int64_t()> epoch = {});
  // Publishes the grasp at a model-space position; `held` sets button bit 0.
  // Returns false when LCM refused the publish (or it could not be signed).
  bool Publish(const Eigen::Vector3d& model_position, bool held);
  int64_t published() const { return seq_; }

 private:
  lcm::LCM* lcm_;
  std::string channel_;
  DeviceMapping mapping_;
  const auth::Tagger* tagger_;
  std::function<int64_t()> epoch_;
  auth::AuthSequence auth_seq_;
  int64_t seq_ = 0;
};

}  // namespace snapthread::viewer
