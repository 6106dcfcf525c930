// snapthread-rogue (a test program, tests/service/rogue_test.cc): a host on the LAN that
// holds no session key (issue 12 "Done when"). Links lcmtypes + messages only: it can read
// and send anything on the multicast group, but can only forge or replay MACs.
//   * answers every device pose with two forged force models (2 kHz at a 1 kHz device),
//     echoing the pose's epoch, seq and utime, with a 2 N force and a copied-looking MAC;
//   * forges solver statuses of its own epoch;
//   * re-publishes every event of a logged genuine session (--replay LOG), in a loop;
//   * sends forged poses and the commands LOAD_SCENE /etc/passwd, LOAD_SCENE /dev/zero,
//     SET_METHOD newton (and the logged, genuinely signed ones via the replay).
// usage: snapthread-rogue URL SESSION DURATION_S [REPLAY_LOG]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "messages/channels.h"
#include "messages/subscribe.h"
#include "snapthread/command_t.hpp"
#include "snapthread/device_state_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"

namespace {

using namespace snapthread;
using Clock = std::chrono::steady_clock;

struct LoggedEvent {
  std::string channel;
  std::vector<uint8_t> data;
};

class Rogue {
 public:
  Rogue(const std::string& url, const std::string& session)
      : lcm_(url), channels_(session), rng_(12) {}
  bool good() { return lcm_.good(); }

  void Run(double duration_s, const std::vector<LoggedEvent>& replay) {
    snapthread::messages::Subscribe<&Rogue::OnPose>(lcm_, channels_.device_state, this);
    const auto start = Clock::now();
    auto next_noise = start;
    size_t replay_at = 0;
    while (Clock::now() - start < std::chrono::duration<double>(duration_s)) {
      lcm_.handleTimeout(1);
      // Replay ~2 logged events per ms: about the rate they were logged at (as
      // lcm-logplayer would), looping over the log.
      for (int i = 0; i < 2 && !replay.empty(); ++i) {
        const LoggedEvent& e = replay[replay_at++ % replay.size()];
        lcm_.publish(e.channel, e.data.data(), static_cast<unsigned>(e.data.size()));
        ++sent_;
      }
      if (Clock::now() >= next_noise) {
        next_noise += std::chrono::milliseconds(20);
        SendForgeries();
      }
    }
    std::printf("rogue: sent %lld messages, answered %lld poses\n",
                static_cast<long long>(sent_), static_cast<long long>(poses_answered_));
  }

 private:
  void Forge(uint8_t* mac) {
    for (int i = 0; i < 32; ++i) mac[i] = static_cast<uint8_t>(rng_());
  }

  void OnPose(const lcm::ReceiveBuffer*, const std::string&, const device_state_t* pose) {
    if (pose->device_id == "rogue") return;  // its own
    // Only the live device's poses (the replayed ones are a minute older): 2 forged
    // models per pose of a 1 kHz device = the 2 kHz.
    newest_utime_ = std::max(newest_utime_, pose->utime);
    if (pose->utime < newest_utime_ - 1000000) return;
    ++poses_answered_;
    for (int k = 0; k < 2; ++k) {
      force_model_t m{};
      m.utime = pose->utime;
      m.seq = ++model_seq_;
      m.device_seq = pose->seq;
      m.device_utime = pose->utime;
      m.status = force_model_t::STATUS_REGULAR;
      for (int i = 0; i < 3; ++i) m.u0[i] = pose->position[i];
      m.f0[0] = 2.0;  // 2 N on the hand
      m.epoch = pose->epoch != 0 ? pose->epoch : 0x5eed;
      m.auth_seq = int64_t{1} << 62;  // "above anything"
      Forge(m.mac);
      lcm_.publish(channels_.force_model, &m);
      ++sent_;
    }
  }

  void SendForgeries() {
    solver_status_t st{};
    st.seq = ++status_seq_;
    st.scene = "rogue";
    st.method = "rogue";
    st.epoch = 0x5eed;
    st.auth_seq = int64_t{1} << 62;
    Forge(st.mac);
    lcm_.publish(channels_.solver_status, &st);
    device_state_t pose{};
    pose.utime = 1;
    pose.seq = ++pose_seq_;
    pose.device_id = "rogue";
    pose.position[0] = 0.01;
    pose.orientation[0] = 1.0;
    pose.epoch = 0x5eed;
    pose.auth_seq = int64_t{1} << 62;
    Forge(pose.mac);
    lcm_.publish(channels_.device_state, &pose);
    static const char* const kCommands[][2] = {
        {"L", "/etc/passwd"}, {"L", "/dev/zero"}, {"M", "newton"}};
    const auto& c = kCommands[pose_seq_ % 3];
    command_t cmd{};
    cmd.utime = 1;
    cmd.command = c[0][0] == 'L' ? command_t::LOAD_SCENE : command_t::SET_METHOD;
    cmd.argument = c[1];
    cmd.epoch = 0x5eed;
    cmd.auth_seq = int64_t{1} << 62;
    Forge(cmd.mac);
    lcm_.publish(channels_.command, &cmd);
    sent_ += 3;
  }

  lcm::LCM lcm_;
  snapthread::messages::Channels channels_;
  std::mt19937 rng_;
  int64_t newest_utime_ = 0;
  int64_t model_seq_ = 0, status_seq_ = 0, pose_seq_ = 0, sent_ = 0, poses_answered_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: snapthread-rogue URL SESSION DURATION_S [REPLAY_LOG]\n");
    return 2;
  }
  std::vector<LoggedEvent> replay;
  if (argc >= 5) {
    lcm::LogFile log(argv[4], "r");
    if (!log.good()) {
      std::fprintf(stderr, "rogue: cannot read %s\n", argv[4]);
      return 2;
    }
    while (const lcm::LogEvent* e = log.readNextEvent()) {
      const auto* d = static_cast<const uint8_t*>(e->data);
      replay.push_back({e->channel, std::vector<uint8_t>(d, d + e->datalen)});
    }
  }
  Rogue rogue(argv[1], argv[2]);
  if (!rogue.good()) return 1;
  rogue.Run(std::atof(argv[3]), replay);
  return 0;
}
