#include "server_inbox.h"

#include <utility>

namespace snapthread::server {

bool ServerInbox::PutPose(const ReceivedPose& pose) {
  bool superseded = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    bool stored = false;
    for (ReceivedPose& p : poses_) {
      if (p.state.grasp == pose.state.grasp && p.state.sender_name == pose.state.sender_name) {
        p = pose;
        superseded = stored = true;
        break;
      }
    }
    if (!stored && poses_.size() >= kMaxGrasps) return true;
    if (!stored) poses_.push_back(pose);
  }
  cv_.notify_one();
  return superseded;
}

bool ServerInbox::PushCommand(const command_t& command) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (commands_.size() >= kMaxPendingCommands) return false;
    commands_.push_back(command);
  }
  cv_.notify_one();
  return true;
}

void ServerInbox::RequestStop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
}

ServerInbox::Taken ServerInbox::Wait(Clock::time_point deadline) {
  std::unique_lock<std::mutex> lock(mutex_);
  cv_.wait_until(lock, deadline,
                 [this] { return stop_ || !poses_.empty() || !commands_.empty(); });
  Taken taken;
  taken.stop = stop_;
  taken.poses.swap(poses_);
  poses_.clear();
  taken.commands.assign(commands_.begin(), commands_.end());
  commands_.clear();
  return taken;
}

}  // namespace snapthread::server
