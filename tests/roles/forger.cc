#include "forger.h"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "messages/subscribe.h"
#include "messages/validate.h"
#include "sample_messages.h"
#include "session_watch.h"

namespace snapthread::roles_test {
namespace {

int64_t RealtimeMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

Forger::Forger(const std::string& session, const std::string& lcm_url, const auth::KeySet* keys,
               ForgerPlan plan)
    : lcm_(lcm_url), channels_(session), keys_(keys), plan_(plan) {
  messages::Subscribe<&Forger::OnDeviceState>(lcm_.lcm(), channels_.device_state, this);
  messages::Subscribe<&Forger::OnStatus>(lcm_.lcm(), channels_.solver_status, this);
  lcm_.Start();
}

Forger::~Forger() {
  Stop();
  lcm_.Stop();
}

void Forger::Start() {
  stop_ = false;
  thread_ = std::thread([this] { Run(); });
}

void Forger::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

ForgerCounts Forger::sent() {
  std::lock_guard<std::mutex> lock(mutex_);
  return sent_;
}

int64_t Forger::poses_heard() {
  std::lock_guard<std::mutex> lock(mutex_);
  return poses_heard_;
}

// The genuine device's latest pose (its own are device_id "forger"): what a model answers.
void Forger::OnDeviceState(const lcm::ReceiveBuffer* rbuf, const std::string&) {
  device_state_t pose;
  if (!messages::DecodeAndValidate(rbuf, &pose, nullptr) || pose.device_id == "forger") return;
  std::lock_guard<std::mutex> lock(mutex_);
  ++poses_heard_;
  pose_seq_ = pose.seq;
  pose_utime_ = pose.utime;
  if (pose.epoch != 0) epoch_ = pose.epoch;
  std::memcpy(position_, pose.position, sizeof position_);
}

// The live epoch, read in clear off the server's statuses (not its own forgeries).
void Forger::OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string&) {
  solver_status_t st;
  if (!messages::DecodeAndValidate(rbuf, &st, nullptr) || st.scene == kForgedMarker) return;
  std::lock_guard<std::mutex> lock(mutex_);
  epoch_ = st.epoch;
}

auth::Tagger Forger::TaggerFor(int64_t i, auth::Role role, const std::string& name) const {
  auth::Tagger t;
  if (keys_ != nullptr) {
    t = keys_->device_status_tagger() != nullptr ? *keys_->device_status_tagger() : keys_->tagger();
    if (keys_->device_status_tagger() != nullptr && i % 2 == 0) t = keys_->tagger();
  }
  if (i % 2 == 1 || keys_ == nullptr) {
    t.role = role;
    t.name = name;
  }
  return t;
}

int64_t Forger::NextSeq() {
  seq_ = std::max(seq_ + 1, RealtimeMicros() * 1000);
  return seq_;
}

void Forger::PublishPose(int64_t i) {
  device_state_t pose = test_support::Sample<device_state_t>();
  int64_t epoch = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    epoch = epoch_;
    std::memcpy(pose.position, position_, sizeof position_);
  }
  pose.position[1] += 0.03;  // well off the genuine hand: a moved thread if it were accepted
  pose.utime = RealtimeMicros();
  pose.seq = i;
  pose.device_id = "forger";
  pose.buttons = 1;
  static const char* const kGrasps[] = {"", "hand", "other"};
  pose.grasp = kGrasps[i % 3];
  pose.snap_fold_id = 0;
  if (!auth::Sign(&pose, channels_.device_state, epoch, NextSeq(), TaggerFor(i, auth::Role::kDevice, "hand"))) return;
  lcm_.lcm().publish(channels_.device_state, &pose);
  std::lock_guard<std::mutex> lock(mutex_);
  ++sent_.poses;
}

void Forger::PublishModel(int64_t i) {
  force_model_t model = test_support::Sample<force_model_t>();
  int64_t epoch = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    epoch = epoch_;
    model.device_seq = pose_seq_;
    model.device_utime = pose_utime_;
    std::memcpy(model.u0, position_, sizeof position_);
  }
  model.utime = RealtimeMicros();
  model.seq = i;
  model.status = force_model_t::STATUS_REGULAR;
  model.f0[0] = 1.5;  // a push the genuine server never asks for here
  model.f0[1] = 1.5;
  model.f0[2] = 0.0;
  model.has_fold = 0;
  model.grasp = "";
  if (!auth::Sign(&model, channels_.force_model, epoch, NextSeq(), TaggerFor(i, auth::Role::kServer, "hand"))) return;
  lcm_.lcm().publish(channels_.force_model, &model);
  std::lock_guard<std::mutex> lock(mutex_);
  ++sent_.models;
}

// Commands, shapes, solver statuses and device statuses.
void Forger::PublishSlow(int64_t i) {
  int64_t epoch = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    epoch = epoch_;
  }
  ForgerCounts sent;
  if (plan_.commands) {
    command_t command = test_support::Sample<command_t>();
    static const int8_t kCommands[] = {command_t::LOAD_SCENE, command_t::SET_METHOD, command_t::RESET};
    static const char* const kArguments[] = {"zeeman", "newton", ""};
    command.utime = RealtimeMicros();
    command.command = kCommands[i % 3];
    command.argument = kArguments[i % 3];
    if (auth::Sign(&command, channels_.command, epoch, NextSeq(), TaggerFor(i, auth::Role::kOperator, "operator"))) {
      lcm_.lcm().publish(channels_.command, &command);
      ++sent.commands;
    }
  }
  if (!plan_.views) {
    std::lock_guard<std::mutex> lock(mutex_);
    sent_.commands += sent.commands;
    return;
  }
  thread_shape_t shape = test_support::SampleShape(12);
  shape.scene = kForgedMarker;
  shape.seq = i;
  if (auth::Sign(&shape, channels_.shape, epoch, NextSeq(), TaggerFor(i, auth::Role::kServer, ""))) {
    lcm_.lcm().publish(channels_.shape, &shape);
    ++sent.shapes;
  }
  solver_status_t status = test_support::Sample<solver_status_t>();
  status.scene = kForgedMarker;
  status.seq = i;
  if (auth::Sign(&status, channels_.solver_status, epoch, NextSeq(), TaggerFor(i, auth::Role::kServer, ""))) {
    lcm_.lcm().publish(channels_.solver_status, &status);
    ++sent.statuses;
  }
  // A status in the name of "hand" (a device speaking for itself is no forgery).
  device_status_t device = test_support::Sample<device_status_t>();
  device.device_id = kForgedMarker;
  if (keys_ != nullptr && keys_->device_public_key() != nullptr) {
    std::memcpy(device.device_public_key, keys_->device_public_key()->data(), sizeof device.device_public_key);
    std::memcpy(device.device_certificate, keys_->device_certificate()->data(), sizeof device.device_certificate);
  }
  if (auth::Sign(&device, channels_.device_status, epoch, NextSeq(), TaggerFor(1, auth::Role::kDevice, "hand"))) {
    lcm_.lcm().publish(channels_.device_status, &device);
    ++sent.device_statuses;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  sent_.commands += sent.commands;
  sent_.shapes += sent.shapes;
  sent_.statuses += sent.statuses;
  sent_.device_statuses += sent.device_statuses;
}

void Forger::Run() {
  for (int64_t i = 0; !stop_; ++i) {
    if (plan_.poses) PublishPose(i);
    if (plan_.models) PublishModel(i);
    if (i % 10 == 0) PublishSlow(i / 10);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

}  // namespace snapthread::roles_test
