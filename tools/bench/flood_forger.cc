#include "flood_forger.h"

#include <algorithm>
#include <chrono>
#include <utility>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "auth/message_mac.h"
#include "auth/session_key.h"
#include "messages/channels.h"
#include "messages/validate.h"
#include "snapthread/command_t.hpp"
#include "snapthread/device_state_t.hpp"
#include "snapthread/device_status_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::flood {

namespace {

int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

// One encoded forgery per channel, built once: the receivers' cost does not depend on
// the bytes changing (every packet is decoded and MAC-checked), the forger's does.
struct ForgedFlood::Prepared {
  std::vector<std::pair<std::string, std::vector<uint8_t>>> messages;
};

namespace {

// Signs `msg` under `key` (not the session's) and appends its encoding; false when it
// would not pass the receivers' validation (then it would not reach their MAC check).
template <class Msg>
bool Add(Msg msg, const std::string& channel, int64_t epoch, const auth::SessionKey& key,
         std::vector<std::pair<std::string, std::vector<uint8_t>>>* out, std::string* error) {
  std::string why;
  if (!auth::Sign(&msg, channel, epoch, int64_t{1} << 62, key) || !messages::Validate(msg, &why)) {
    *error = "forged message for " + channel + " is not valid: " + why;
    return false;
  }
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  out->emplace_back(channel, std::move(bytes));
  return true;
}

}  // namespace

ForgedFlood::ForgedFlood(ForgerOptions options) : options_(std::move(options)) {}

ForgedFlood::~ForgedFlood() { Stop(); }

bool ForgedFlood::Start(std::string* error) {
  if (thread_.joinable()) return true;
  try {
    const messages::Channels ch(options_.session);
    auth::InitSodium();
    const auth::SessionKey key = auth::SessionKey::Generate();  // not the session's
    auto prepared = std::make_unique<Prepared>();
    auto& out = prepared->messages;
    const int64_t e = options_.epoch;

    device_state_t pose{};
    pose.utime = 1;
    pose.seq = 1;
    pose.device_id = "forged";
    pose.position[0] = 0.01;
    pose.orientation[0] = 1.0;

    force_model_t model{};
    model.utime = 1;
    model.seq = 1;
    model.status = force_model_t::STATUS_REGULAR;
    model.f0[2] = options_.forged_force_n;
    for (int i = 0; i < 3; ++i) model.K[i][i] = -1000.0;
    model.q0[0] = 1.0;
    model.fold_q[0] = 1.0;
    model.fold_normal[0] = 1.0;

    thread_shape_t shape{};
    shape.scene = "forged";
    shape.model = "curve2d";
    shape.num_nodes = options_.forged_shape_nodes;
    for (int i = 0; i < shape.num_nodes; ++i) shape.positions.push_back({1.0 * i, 0.0, 5.0});
    shape.grip_direction[0] = 1.0;

    solver_status_t status{};
    status.scene = "forged";
    status.method = "newton";

    device_status_t dstatus{};
    dstatus.device_id = "forged";

    command_t command{};
    command.command = command_t::LOAD_SCENE;
    command.argument = "forged";

    if (!Add(pose, ch.device_state, e, key, &out, error) || !Add(model, ch.force_model, e, key, &out, error) ||
        !Add(shape, ch.shape, e, key, &out, error) || !Add(status, ch.solver_status, e, key, &out, error) ||
        !Add(dstatus, ch.device_status, e, key, &out, error) || !Add(command, ch.command, e, key, &out, error)) {
      return false;
    }
    prepared_ = std::move(prepared);
  } catch (const std::exception& ex) {
    *error = std::string("flood: ") + ex.what();
    return false;
  }
  stop_ = false;
  start_ns_ = NowNs();
  stop_ns_ = 0;
  thread_ = std::thread([this] { Run(); });
  return true;
}

void ForgedFlood::Stop() {
  if (!thread_.joinable()) return;
  stop_ = true;
  thread_.join();
  stop_ns_ = NowNs();
}

double ForgedFlood::AchievedRatePerChannel() const {
  const int64_t start = start_ns_.load();
  if (start == 0) return 0.0;
  const int64_t end = stop_ns_.load() != 0 ? stop_ns_.load() : NowNs();
  const double s = 1e-9 * static_cast<double>(end - start);
  return s > 0 ? static_cast<double>(sent()) / kChannels / s : 0.0;
}

void ForgedFlood::Run() {
  lcm::LCM lcm(options_.lcm_url);  // publishes only: LCM opens no receive socket
  if (!lcm.good()) {
    failures_.fetch_add(1);
    return;
  }
  const auto& messages = prepared_->messages;
  const double rate = options_.rate_per_channel_hz;
  const int64_t t0 = NowNs();
  uint64_t rounds = 0;  // one message on every channel per round
  while (!stop_.load(std::memory_order_relaxed)) {
    const double elapsed_s = 1e-9 * static_cast<double>(NowNs() - t0);
    auto due = static_cast<uint64_t>(elapsed_s * rate);
    // After a long deschedule, do not burst more than 20 ms worth: a flooder paces itself.
    const auto burst = static_cast<uint64_t>(std::max(1.0, 0.02 * rate));
    if (due > rounds + burst) rounds = due - burst;
    while (rounds < due && !stop_.load(std::memory_order_relaxed)) {
      for (const auto& [channel, bytes] : messages) {
        if (lcm.publish(channel, bytes.data(), static_cast<unsigned>(bytes.size())) == 0) {
          sent_.fetch_add(1, std::memory_order_relaxed);
        } else {
          failures_.fetch_add(1, std::memory_order_relaxed);
        }
      }
      ++rounds;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

}  // namespace snapthread::flood
