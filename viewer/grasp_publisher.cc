#include "grasp_publisher.h"

#include "snapthread/device_state_t.hpp"
#include "messages/channels.h"
#include "messages/pose_mapping.h"
#include "realtime/clock.h"
#include "messages/validate.h"

namespace snapthread::viewer {

GraspPublisher::GraspPublisher(lcm::LCM* lcm, const std::string& session,
                               const DeviceMapping& mapping)
    : lcm_(lcm), channel_(transport::Channels(session).device_state), mapping_(mapping) {}

bool GraspPublisher::Publish(const Eigen::Vector3d& model_position, bool held) {
  device_state_t msg;
  msg.utime = transport::MonotonicMicros();  // device poses carry CLOCK_MONOTONIC
  msg.seq = ++seq_;
  msg.device_id = "viewer-mouse";
  const Eigen::Vector3d p = messages::ModelPointToDevice(mapping_, model_position);
  for (int i = 0; i < 3; ++i) msg.position[i] = p[i];
  msg.orientation[0] = 1.0;  // identity: grip direction +x
  msg.orientation[1] = msg.orientation[2] = msg.orientation[3] = 0.0;
  msg.buttons = held ? 1 : 0;
  if (!transport::Validate(msg, nullptr)) return false;  // e.g. a non-finite drag target
  return lcm_->publish(channel_, &msg) == 0;
}

}  // namespace snapthread::viewer
