#include "flood_forger.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <utility>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "auth/credential.h"
#include "auth/key_file.h"
#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "auth/session_key.h"
#include "messages/channels.h"
#include "messages/subscribe.h"
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

// The channels, in the order the forgeries are built.
enum class Channel { kPose, kModel, kShape, kStatus, kDeviceStatus, kCommand };

// The sender the genuine messages of a channel claim: the device "hand" (the scene's only
// grasp), the server (force models name the device they are for) or the operator.
auth::Role ClaimedRole(Channel c) {
  if (c == Channel::kPose || c == Channel::kDeviceStatus) return auth::Role::kDevice;
  return c == Channel::kCommand ? auth::Role::kOperator : auth::Role::kServer;
}
const char* ClaimedName(Channel c) {
  if (c == Channel::kCommand) return "operator";
  return c == Channel::kShape || c == Channel::kStatus ? "" : "hand";
}

// What a forger of each kind holds.
struct ForgerKeys {
  std::optional<auth::SessionKey> own;  // kNoKey
  std::optional<auth::KeySet> held;     // this session's credential
  std::optional<auth::KeySet> other_server, other_device, other_operator;  // kOtherSessionRoot
};

ForgerKeys MakeKeys(const ForgerOptions& o) {
  ForgerKeys k;
  using auth::Role;
  switch (o.kind) {
    case ForgerKind::kNoKey:
      k.own.emplace(auth::SessionKey::Generate());  // not the session's
      break;
    case ForgerKind::kObserver:
    case ForgerKind::kOtherDevice:
    case ForgerKind::kOperator: {
      const auth::SessionKey root = auth::LoadKey(auth::KeyLocation{o.root_key_path, "forger root key"});
      const Role role = o.kind == ForgerKind::kObserver ? Role::kObserver
                        : o.kind == ForgerKind::kOperator ? Role::kOperator : Role::kDevice;
      // The credential alone, as the forger's host would hold it (no root).
      k.held.emplace(auth::KeySet::FromCredential(auth::IssueCredential(
          root, role, role == Role::kObserver ? "" : o.forger_name, auth::kNeverExpires)));
      break;
    }
    case ForgerKind::kOtherSessionRoot: {
      const auth::SessionKey other = auth::SessionKey::Generate();
      k.other_server.emplace(auth::KeySet::ForRole(other, Role::kServer));
      k.other_device.emplace(auth::KeySet::ForRole(other, Role::kDevice, "hand"));
      k.other_operator.emplace(auth::KeySet::ForRole(other, Role::kOperator, "operator"));
      break;
    }
  }
  return k;
}

// How a forger of `kind` tags a message on `c` (see ForgerKind).
auth::Tagger TaggerFor(ForgerKind kind, const ForgerKeys& k, Channel c) {
  auth::Tagger t;
  t.role = ClaimedRole(c);
  t.name = ClaimedName(c);
  switch (kind) {
    case ForgerKind::kNoKey:
      t.mac_key = &*k.own;
      t.key_id = auth::RootKeyId(*k.own);
      break;
    case ForgerKind::kObserver:
      t.mac_key = &k.held->read_key();
      break;
    case ForgerKind::kOtherDevice: {
      const auth::Tagger own = k.held->tagger();
      t.mac_key = own.mac_key;
      t.key_id = own.key_id;
      t.expires_unix_s = own.expires_unix_s;
      if (c == Channel::kPose) t.name = own.name;  // its own name: a grasp it does not hold
      break;
    }
    case ForgerKind::kOperator:
      t = k.held->tagger();  // its own role and name, a MAC that verifies
      break;
    case ForgerKind::kOtherSessionRoot: {
      const auth::KeySet& mac_holder = c == Channel::kCommand ? *k.other_operator : *k.other_device;
      t.mac_key = mac_holder.mac_key();
      t.key_id = mac_holder.credential()->key_id;
      t.expires_unix_s = mac_holder.expires_unix_s();
      if (t.role == auth::Role::kServer) t.signer = k.other_server->tagger().signer;
      if (c == Channel::kDeviceStatus) t.signer = k.other_device->device_status_tagger()->signer;
      break;
    }
  }
  return t;
}

// Whether a forger of `kind` floods channel `c` (not where its role may speak).
bool Floods(ForgerKind kind, Channel c) {
  if (kind == ForgerKind::kOperator) return c != Channel::kCommand;
  if (kind == ForgerKind::kOtherDevice) return c != Channel::kDeviceStatus;
  return true;
}

// The genuine server's epoch, from a SOLVER_STATUS it signed (what a credential holder can
// check), or nullopt after `seconds`.
class EpochListener {
 public:
  EpochListener(const std::string& url, const std::string& channel, const auth::PublicKey& server)
      : lcm_(url), server_(server) {
    if (lcm_.good()) messages::Subscribe<&EpochListener::OnStatus>(&lcm_, channel, this);
  }
  std::optional<int64_t> Wait(double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!epoch_ && lcm_.good() && std::chrono::steady_clock::now() < end) lcm_.handleTimeout(50);
    return epoch_;
  }

 private:
  void OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    solver_status_t st;
    if (messages::DecodeAndValidate(rbuf, &st, nullptr) &&
        st.sender_role == static_cast<int8_t>(auth::Role::kServer) &&
        auth::VerifySignature(rbuf->data, rbuf->data_size, channel, server_)) {
      epoch_ = st.epoch;
    }
  }
  lcm::LCM lcm_;
  auth::PublicKey server_;
  std::optional<int64_t> epoch_;
};

}  // namespace

const char* ForgerKindName(ForgerKind kind) {
  switch (kind) {
    case ForgerKind::kNoKey: return "no key";
    case ForgerKind::kObserver: return "observer credential";
    case ForgerKind::kOtherDevice: return "another device's credential";
    case ForgerKind::kOperator: return "operator credential";
    case ForgerKind::kOtherSessionRoot: return "another session's root key";
  }
  return "?";
}

// One encoded forgery per channel, built once: the receivers' cost does not depend on
// the bytes changing (every packet is decoded and MAC-checked), the forger's does.
struct ForgedFlood::Prepared {
  std::vector<std::pair<std::string, std::vector<uint8_t>>> messages;
};

namespace {

// Tags `msg` as a forger of `kind` does on channel `c` and appends its encoding; false
// when it would not pass the receivers' validation (then it would not reach their tag
// check). A channel the kind does not flood is skipped.
template <class Msg>
bool Add(Msg msg, Channel c, const std::string& channel, int64_t epoch, ForgerKind kind, const ForgerKeys& keys,
         std::vector<std::pair<std::string, std::vector<uint8_t>>>* out, std::string* error) {
  if (!Floods(kind, c)) return true;
  std::string why;
  if (!auth::Sign(&msg, channel, epoch, int64_t{1} << 62, TaggerFor(kind, keys, c)) ||
      !messages::Validate(msg, &why)) {
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
    const ForgerKeys keys = MakeKeys(options_);
    auto prepared = std::make_unique<Prepared>();
    auto& out = prepared->messages;
    int64_t e = options_.epoch;
    if (keys.held) {
      EpochListener listener(options_.lcm_url, ch.solver_status, keys.held->server_public_key());
      if (const std::optional<int64_t> genuine = listener.Wait(options_.learn_epoch_s)) e = *genuine;
    }
    const ForgerKind kind = options_.kind;

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
    if (keys.other_device) {  // a device key pair and certificate, of the other session
      std::copy(keys.other_device->device_public_key()->begin(), keys.other_device->device_public_key()->end(),
                dstatus.device_public_key);
      std::copy(keys.other_device->device_certificate()->begin(), keys.other_device->device_certificate()->end(),
                dstatus.device_certificate);
    }

    command_t command{};
    command.command = command_t::LOAD_SCENE;
    command.argument = "forged";

    if (!Add(pose, Channel::kPose, ch.device_state, e, kind, keys, &out, error) ||
        !Add(model, Channel::kModel, ch.force_model, e, kind, keys, &out, error) ||
        !Add(shape, Channel::kShape, ch.shape, e, kind, keys, &out, error) ||
        !Add(status, Channel::kStatus, ch.solver_status, e, kind, keys, &out, error) ||
        !Add(dstatus, Channel::kDeviceStatus, ch.device_status, e, kind, keys, &out, error) ||
        !Add(command, Channel::kCommand, ch.command, e, kind, keys, &out, error)) {
      return false;
    }
    channels_ = static_cast<int>(out.size());
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
  return s > 0 ? static_cast<double>(sent()) / channels_ / s : 0.0;
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
