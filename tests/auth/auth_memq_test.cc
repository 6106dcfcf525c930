// The whole exchange over LCM memq://, with the auth room only and the roles' keys: the
// device learns the epoch from the server's signed status, its poses (MAC, device key)
// are answered by force models MAC'd under its key, and a key-less attacker's, an
// observer's (its read key) and another session's forged, replayed and re-keyed messages
// are all refused and counted (never handed on), while the genuine exchange keeps working.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "auth/freshness_filter.h"
#include "auth/key_set.h"
#include "auth/message_gate.h"
#include "auth/message_mac.h"
#include "auth/pose_echo_window.h"
#include "auth/session_epoch.h"
#include "messages/subscribe.h"
#include "messages/validate.h"
#include "sample_messages.h"

namespace snapthread::auth {
namespace {

const std::string kStatus = "T_SOLVER_STATUS";
const std::string kPose = "T_DEVICE_STATE";
const std::string kModel = "T_FORCE_MODEL";

using Bytes = std::vector<uint8_t>;

// How the server tags a force model for `device`.
Tagger ModelTagger(const KeySet& device) { return device.ForceModelTagger(); }

Bytes Copy(const lcm::ReceiveBuffer* rbuf) {
  const auto* p = static_cast<const uint8_t*>(rbuf->data);
  return Bytes(p, p + rbuf->data_size);
}

// The device's receive side, as the device client will do it.
class Device {
 public:
  Device(lcm::LCM* lcm, const KeySet* keys) : lcm_(lcm), keys_(keys) {
    messages::Subscribe<&Device::OnStatus>(lcm, kStatus, this);
    messages::Subscribe<&Device::OnModel>(lcm, kModel, this);
  }

  void OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    solver_status_t msg;
    if (!messages::DecodeAndValidate(rbuf, &msg, nullptr)) return;
    if (AdmitSigned(rbuf->data, rbuf->data_size, msg, channel, keys_->server_public_key(), &status_filter_) ==
        Reason::kAccepted) {
      model_filter_.SetEpoch(status_filter_.epoch());
    }
  }

  void OnModel(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    force_model_t msg;
    if (!messages::DecodeAndValidate(rbuf, &msg, nullptr)) {
      ++malformed_;
      return;
    }
    if (AdmitForceModel(rbuf->data, rbuf->data_size, msg, channel, *keys_->mac_key(), *sent_, &model_filter_) ==
        Reason::kAccepted) {
      rendered_.push_back(msg.device_seq);
    }
  }

  void SendPose() {
    device_state_t pose = test_support::Sample<device_state_t>();
    pose.seq = ++pose_seq_;
    pose.utime = 1000 * pose.seq + 7;
    const int64_t epoch = status_filter_.epoch();
    ASSERT_TRUE(Sign(&pose, kPose, epoch, seq_.Next(), keys_->tagger()));
    sent_->Record(epoch, pose.seq, pose.utime);
    lcm_->publish(kPose, &pose);
  }

  // What goes into device_status_t.models_rejected.
  uint64_t models_rejected() const { return malformed_ + model_filter_.rejected(); }

  FreshnessFilter status_filter_{kStatus, FreshnessFilter::EpochPolicy::kAdopt};
  FreshnessFilter model_filter_{kModel};
  std::unique_ptr<PoseEchoWindow> sent_ = std::make_unique<PoseEchoWindow>();
  std::vector<int64_t> rendered_;  // device_seq of every model accepted
  uint64_t malformed_ = 0;
  int64_t pose_seq_ = 0;

 private:
  lcm::LCM* lcm_;
  const KeySet* keys_;
  AuthSequence seq_;
};

// The server's side: answers every admitted pose with a signed model echoing it.
class Server {
 public:
  // `server` signs statuses; `device` is the one device it answers (its MAC key).
  Server(lcm::LCM* lcm, const KeySet* server, const KeySet* device)
      : lcm_(lcm),
        server_(server),
        device_(device),
        subscription_(messages::Subscribe<&Server::OnPose>(lcm, kPose, this)) {}
  ~Server() { lcm_->unsubscribe(subscription_); }
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  void OnPose(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    device_state_t pose;
    if (!messages::DecodeAndValidate(rbuf, &pose, nullptr)) return;
    if (Admit(rbuf->data, rbuf->data_size, pose, channel, *device_->mac_key(), &pose_filter_) != Reason::kAccepted ||
        pose.sender_role != static_cast<int8_t>(Role::kDevice) || pose.sender_name != device_->name()) {
      return;
    }
    force_model_t m = test_support::Sample<force_model_t>();
    m.device_seq = pose.seq;
    m.device_utime = pose.utime;
    ASSERT_TRUE(Sign(&m, kModel, epoch_, seq_.Next(), ModelTagger(*device_)));
    lcm_->publish(kModel, &m);
    ++answered_;
  }

  void SendStatus() {
    solver_status_t s = test_support::Sample<solver_status_t>();
    ASSERT_TRUE(Sign(&s, kStatus, epoch_, seq_.Next(), server_->tagger()));
    lcm_->publish(kStatus, &s);
  }

  const int64_t epoch_ = NewEpoch();
  FreshnessFilter pose_filter_{kPose, FreshnessFilter::EpochPolicy::kFixed, epoch_};
  int answered_ = 0;

 private:
  lcm::LCM* lcm_;
  const KeySet* server_;
  const KeySet* device_;
  lcm::Subscription* subscription_;
  AuthSequence seq_;
};

// Everything on the models and status channels, as lcm-logger would keep it.
struct Recorder {
  void OnAny(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    (channel == kModel ? models : statuses).push_back(Copy(rbuf));
  }
  std::vector<Bytes> models, statuses;
};

void Drain(lcm::LCM* lcm) {
  while (lcm->handleTimeout(0) > 0) {
  }
}

TEST(AuthOverMemqTest, ForgedReplayedAndRekeyedMessagesAreRefusedAndCounted) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  const SessionKey root = SessionKey::Generate();
  const KeySet server_keys = KeySet::ForRole(root, Role::kServer);
  const KeySet device_keys = KeySet::ForRole(root, Role::kDevice, "hand");
  Recorder log;
  messages::Subscribe<&Recorder::OnAny>(lcm, kModel, &log);
  messages::Subscribe<&Recorder::OnAny>(lcm, kStatus, &log);
  Device device(&lcm, &device_keys);
  auto server = std::make_unique<Server>(&lcm, &server_keys, &device_keys);

  // Before any status the device has no epoch: the server refuses its poses.
  device.SendPose();
  Drain(&lcm);
  EXPECT_EQ(server->answered_, 0);
  EXPECT_EQ(server->pose_filter_.rejected(Reason::kForeignEpoch), 1u);

  // Genuine session: status, then 20 poses answered by 20 accepted models.
  server->SendStatus();
  Drain(&lcm);
  ASSERT_EQ(device.status_filter_.epoch(), server->epoch_);
  for (int i = 0; i < 20; ++i) device.SendPose();
  Drain(&lcm);
  EXPECT_EQ(server->answered_, 20);
  ASSERT_EQ(device.rendered_.size(), 20u);
  EXPECT_EQ(device.models_rejected(), 0u);

  // 1. Forged models answering the device's last pose, with the sniffed epoch and a high
  //    sequence number, valid LCM encoding, but no key (tag left zero).
  for (int i = 0; i < 50; ++i) {
    force_model_t forged = test_support::Sample<force_model_t>();
    forged.f0[0] = 2.9;
    forged.device_seq = device.pose_seq_;
    forged.device_utime = 1000 * device.pose_seq_ + 7;
    forged.epoch = server->epoch_;
    forged.auth_seq = INT64_MAX - i;
    lcm.publish(kModel, &forged);
  }
  // 2. The same, tagged as the server tags them by another session's root holder (its
  //    key for a device "hand"), and by an observer of this session (the only secret it
  //    holds: the read key).
  const KeySet rogue_device = KeySet::ForRole(SessionKey::Generate(), Role::kDevice, "hand");
  const KeySet observer = KeySet::ForRole(root, Role::kObserver);
  Tagger observer_tagger;
  observer_tagger.name = "hand";
  observer_tagger.mac_key = &observer.read_key();
  for (int i = 0; i < 20; ++i) {
    force_model_t forged = test_support::Sample<force_model_t>();
    forged.device_seq = device.pose_seq_;
    forged.device_utime = 1000 * device.pose_seq_ + 7;
    ASSERT_TRUE(Sign(&forged, kModel, server->epoch_, INT64_MAX - i,
                     i < 10 ? ModelTagger(rogue_device) : observer_tagger));
    lcm.publish(kModel, &forged);
  }
  Drain(&lcm);
  // 3. The log of the models channel played back (lcm-logplayer): genuine and forged.
  const std::vector<Bytes> logged = log.models;
  ASSERT_EQ(logged.size(), 90u);  // 20 genuine + 70 forged
  for (const Bytes& b : logged) lcm.publish(kModel, b.data(), static_cast<unsigned>(b.size()));
  // 4. Forged poses to the server (no key; another session's device key): never answered.
  for (int i = 0; i < 30; ++i) {
    device_state_t pose = test_support::Sample<device_state_t>();
    if (i < 20) {
      pose.epoch = server->epoch_;
      pose.auth_seq = INT64_MAX - i;
    } else {
      ASSERT_TRUE(Sign(&pose, kPose, server->epoch_, INT64_MAX - i, rogue_device.tagger()));
    }
    lcm.publish(kPose, &pose);
  }
  Drain(&lcm);

  EXPECT_EQ(device.rendered_.size(), 20u);  // nothing forged or replayed was accepted
  EXPECT_EQ(device.model_filter_.rejected(Reason::kBadMac), 70u + 70u);  // + the replayed forgeries
  EXPECT_EQ(device.model_filter_.rejected(Reason::kStaleSequence), 20u);
  EXPECT_EQ(device.models_rejected(), 160u);
  EXPECT_EQ(server->answered_, 20);
  EXPECT_EQ(server->pose_filter_.rejected(Reason::kBadMac), 30u);
  std::string line;
  ASSERT_TRUE(device.model_filter_.TakeLogLine(0, &line));
  EXPECT_NE(line.find("T_FORCE_MODEL: 160 rejected (bad MAC 140, replayed or old sequence number 20)"),
            std::string::npos)
      << line;

  // The genuine exchange goes on.
  for (int i = 0; i < 5; ++i) device.SendPose();
  Drain(&lcm);
  EXPECT_EQ(device.rendered_.size(), 25u);

  // The server restarts (new epoch). Its first status moves the device over; the old
  // session's status and models played back afterwards move nothing.
  const std::vector<Bytes> old_statuses = log.statuses;
  const std::vector<Bytes> old_models = log.models;
  server.reset();
  server = std::make_unique<Server>(&lcm, &server_keys, &device_keys);
  server->SendStatus();
  Drain(&lcm);
  ASSERT_EQ(device.status_filter_.epoch(), server->epoch_);
  for (const Bytes& b : old_statuses) lcm.publish(kStatus, b.data(), static_cast<unsigned>(b.size()));
  for (const Bytes& b : old_models) lcm.publish(kModel, b.data(), static_cast<unsigned>(b.size()));
  Drain(&lcm);
  EXPECT_EQ(device.status_filter_.epoch(), server->epoch_);
  EXPECT_EQ(device.status_filter_.rejected(Reason::kStaleSequence), old_statuses.size());
  EXPECT_EQ(device.rendered_.size(), 25u);
  // The 45 genuine models of the old session (20 + 20 replayed + 5) and its status.
  EXPECT_EQ(device.model_filter_.rejected(Reason::kForeignEpoch), 45u);
  EXPECT_EQ(old_statuses.size(), 1u);
  for (int i = 0; i < 5; ++i) device.SendPose();
  Drain(&lcm);
  EXPECT_EQ(device.rendered_.size(), 30u);
}

}  // namespace
}  // namespace snapthread::auth
