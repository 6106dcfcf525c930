#include "grasp_publisher.h"

#include <utility>

#include "auth/message_mac.h"
#include "snapthread/device_state_t.hpp"
#include "messages/channels.h"
#include "messages/publish.h"
#include "messages/pose_mapping.h"
#include "realtime/clock.h"
#include "messages/validate.h"

namespace snapthread::viewer {

GraspPublisher::GraspPublisher(lcm::LCM* lcm, const std::string& session,
                               const DeviceMapping& mapping, const auth::Tagger* tagger,
                               std::function<int64_t()> epoch)
    : lcm_(lcm),
      channel_(messages::Channels(session).device_state),
      mapping_(mapping),
      tagger_(tagger),
      epoch_(std::move(epoch)) {}

bool GraspPublisher::Publish(const Eigen::Vector3d& model_position, bool held) {
  device_state_t msg{};  // every field set: the trailer too, checked by Validate below
  msg.utime = realtime::MonotonicMicros();  // device poses carry CLOCK_MONOTONIC
  msg.seq = ++seq_;
  msg.device_id = "viewer-mouse";
  const Eigen::Vector3d p = messages::ModelPointToDevice(mapping_, model_position);
  for (int i = 0; i < 3; ++i) msg.position[i] = p[i];
  msg.orientation[0] = 1.0;  // identity: grip direction +x
  msg.orientation[1] = msg.orientation[2] = msg.orientation[3] = 0.0;
  msg.buttons = held ? 1 : 0;
  if (!messages::Validate(msg, nullptr)) return false;  // e.g. a non-finite drag target
  if (tagger_ != nullptr &&
      !auth::Sign(&msg, channel_, epoch_ ? epoch_() : 0, auth_seq_.Next(), *tagger_)) {
    return false;
  }
  // In clear, or sealed when the viewer runs with --encrypt.
  return messages::Publish(lcm_, channel_, msg) == 0;
}

}  // namespace snapthread::viewer
