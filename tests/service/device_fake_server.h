// What the device's process tests share: snapthread-device as a child process, and a fake
// server in the test process over udpm on loopback. The fake server answers every pose
// with the local model of a linear spring anchored at the device origin,
//   F(u) = -k u  ->  f0 = -k u0, K = -k I (plus a negative stiffness along z to clamp),
// tagged as the real server does (MAC with the device's key, sender_role server,
// sender_name the device) with its own epoch, which it announces in a solver status signed
// with the server key every 50 ms (the device learns the epoch from it, as from the real
// server).
#pragma once

#include <atomic>
#include <chrono>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/role.h"
#include "auth/session_epoch.h"
#include "auth/session_key.h"
#include "messages/channels.h"
#include "messages/subscribe.h"
#include "messages/validate.h"
#include "snapthread/device_state_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "test_support.h"

namespace snapthread::device::testing {

inline constexpr double kSpringNPerM = 40.0;
inline constexpr double kNegativeStiffnessNPerM = 25.0;

// Writes <dir>/scene.yaml, the scene the device's process tests drive (named `name`): the
// zeeman model, its grasp on the path from (-2, 3) to (2, 1.5) model units = (-2, 0.5) cm
// to (2, -1) cm on the device. Returns its path.
inline std::string WriteDeviceScene(const std::string& dir, const std::string& name) {
  const std::string path = dir + "/scene.yaml";
  std::ofstream f(path);
  f << "name: " << name << "\nmodel: zeeman\n"
       "grasp:\n  start: [0, 2.5]\n  path: [[-2, 3.0], [2, 1.5]]\n"
       "device:\n  model_units_per_metre: 100\n  model_origin: [0, 2.5, 0]\n";
  return path;
}

// A child process with stdout/stderr in <prefix>.out / <prefix>.err.
class DeviceProcess : public test_support::ChildProcess {
 public:
  DeviceProcess(const std::vector<std::string>& args, const std::string& prefix)
      : ChildProcess(args, test_support::OutputFiles(prefix + ".out", prefix + ".err")) {}
  // Exit code, or -1 on a timeout (then the process is killed).
  int ExitCode(double timeout_s) {
    int code = -1;
    return WaitOrKill(timeout_s, &code) ? code : -1;
  }
};

// The fake server: answers each device pose with the spring's local model, MACed with
// device `device_name`'s key issued from the root key `root` (the device's own key when it
// runs on that device's credential, or on the root key as that device), with its own
// epoch, which it announces in a solver status signed with the server key every 50 ms
// (the device learns the epoch from it, as from the real server).
class FakeServer {
 public:
  FakeServer(const std::string& session, const auth::SessionKey* root,
             const std::string& lcm_url = test_support::kLoopbackLcmUrl,
             const std::string& device_name = "hand")
      : channels_(session),
        lcm_(lcm_url),
        server_keys_(auth::KeySet::ForRole(*root, auth::Role::kServer)),
        device_keys_(auth::KeySet::ForRole(*root, auth::Role::kDevice, device_name)),
        epoch_(auth::NewEpoch()) {
    model_tagger_ = device_keys_.ForceModelTagger();
    if (!lcm_.good()) return;
    messages::Subscribe<&FakeServer::OnPose>(lcm_, channels_.device_state, this);
    thread_ = std::thread([this] {
      auto next_status = std::chrono::steady_clock::now();
      while (!stop_.load()) {
        lcm_.handleTimeout(10);
        if (std::chrono::steady_clock::now() >= next_status) {
          PublishStatus();
          next_status += std::chrono::milliseconds(50);
        }
      }
    });
  }
  ~FakeServer() { Stop(); }
  bool good() { return lcm_.good(); }
  void Stop() {
    stop_.store(true);
    if (thread_.joinable()) thread_.join();
  }
  int poses() const { return poses_.load(); }
  int64_t epoch() const { return epoch_; }
  int statuses_sent() const { return statuses_sent_.load(); }

 private:
  void OnPose(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    device_state_t pose;
    if (!messages::DecodeAndValidate(rbuf, &pose, nullptr)) return;
    poses_.fetch_add(1);
    force_model_t m{};
    m.utime = 0;
    m.seq = ++seq_;
    m.device_seq = pose.seq;
    m.device_utime = pose.utime;
    // Every 100th model reports a snap (the device counts snaps felt).
    m.status = m.seq % 100 == 0 ? force_model_t::STATUS_SNAPPED : force_model_t::STATUS_REGULAR;
    for (int i = 0; i < 3; ++i) {
      m.u0[i] = pose.position[i];
      m.f0[i] = -kSpringNPerM * pose.position[i];
      m.K[i][i] = -kSpringNPerM;
    }
    // A negative stiffness along z (dF_z/dz > 0), which the device must clamp to zero in
    // every model. The sim-path stays at z = 0, so the spring law is unaffected.
    m.K[2][2] = +kNegativeStiffnessNPerM;
    if (!auth::Sign(&m, channels_.force_model, epoch_, auth_seq_.Next(), model_tagger_)) return;
    lcm_.publish(channels_.force_model, &m);
  }

  void PublishStatus() {
    solver_status_t st{};
    st.seq = ++status_seq_;
    st.scene = "fake";
    st.method = "spring";
    if (!auth::Sign(&st, channels_.solver_status, epoch_, auth_seq_.Next(), server_keys_.tagger())) return;
    if (lcm_.publish(channels_.solver_status, &st) == 0) statuses_sent_.fetch_add(1);
  }

  messages::Channels channels_;
  lcm::LCM lcm_;
  auth::KeySet server_keys_;
  auth::KeySet device_keys_;
  auth::Tagger model_tagger_;  // the handler thread's only
  int64_t epoch_;
  auth::AuthSequence auth_seq_;
  int64_t status_seq_ = 0;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<int> poses_{0};
  std::atomic<int> statuses_sent_{0};
  int64_t seq_ = 0;
};

}  // namespace snapthread::device::testing
