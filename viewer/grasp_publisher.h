// Mouse grasp mode: the viewer drives a session like a device would, publishing
// device_state_t on <SESSION>_DEVICE_STATE. Positions in the message are device metres, so the
// scene's DeviceMapping (device -> model) is inverted (messages::ModelPointToDevice).
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include <Eigen/Core>
#include <lcm/lcm-cpp.hpp>

#include "scene/scene.h"

namespace snapthread::viewer {

class GraspPublisher {
 public:
  GraspPublisher(lcm::LCM* lcm, const std::string& session, const DeviceMapping& mapping);
  // Publishes the grasp at a model-space position; `held` sets button bit 0.
  // Returns false when LCM refused the publish.
  bool Publish(const Eigen::Vector3d& model_position, bool held);
  int64_t published() const { return seq_; }

 private:
  lcm::LCM* lcm_;
  std::string channel_;
  DeviceMapping mapping_;
  int64_t seq_ = 0;
};

}  // namespace snapthread::viewer
