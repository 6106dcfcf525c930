#include "session_watch.h"

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <thread>

#include "auth/device_certificate.h"
#include "auth/message_mac.h"
#include "messages/subscribe.h"
#include "messages/validate.h"
#include "snapthread/device_status_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::roles_test {
namespace {

using Clock = std::chrono::steady_clock;

// Polls `get` every 10 ms until it gives a view that arrived after `since`.
template <class View, class Get>
std::optional<View> NextAfter(Clock::time_point since, double timeout_s, const Get& get) {
  const auto deadline = since + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  while (true) {
    std::optional<View> v = get();
    if (v && v->at > since) return v;
    if (Clock::now() > deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

}  // namespace

std::map<std::string, int64_t> ParseRefusals(const std::string& text) {
  std::map<std::string, int64_t> out;
  std::istringstream in(text);
  std::string item;
  while (in >> item) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos) continue;
    out[item.substr(0, eq)] += std::atoll(item.c_str() + eq + 1);
  }
  return out;
}

int64_t Refusals(const std::string& text, const std::string& key) {
  int64_t n = 0;
  for (const auto& [k, count] : ParseRefusals(text)) {
    if (k == key || k.rfind(key + "/", 0) == 0) n += count;
  }
  return n;
}

int64_t TotalRefusals(const std::string& text) {
  int64_t n = 0;
  for (const auto& entry : ParseRefusals(text)) n += entry.second;
  return n;
}

SessionWatch::SessionWatch(const std::string& session, const std::string& lcm_url,
                           std::vector<auth::PublicKey> server_keys)
    : lcm_(lcm_url), channels_(session), server_keys_(std::move(server_keys)) {
  messages::Subscribe<&SessionWatch::OnStatus>(lcm_.lcm(), channels_.solver_status, this);
  messages::Subscribe<&SessionWatch::OnShape>(lcm_.lcm(), channels_.shape, this);
  messages::Subscribe<&SessionWatch::OnDeviceStatus>(lcm_.lcm(), channels_.device_status, this);
  lcm_.Start();
}

SessionWatch::~SessionWatch() { lcm_.Stop(); }

void SessionWatch::AddServerKey(const auth::PublicKey& key) {
  std::lock_guard<std::mutex> lock(mutex_);
  server_keys_.push_back(key);
}

bool SessionWatch::VerifiedByServer(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auth::PublicKey& key : server_keys_) {
    if (auth::VerifySignature(rbuf->data, rbuf->data_size, channel, key)) return true;
  }
  return false;
}

void SessionWatch::OnStatus(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  solver_status_t st;
  if (!messages::DecodeAndValidate(rbuf, &st, nullptr)) return;
  const bool forged = st.scene == kForgedMarker;
  const bool ok = VerifiedByServer(rbuf, channel);
  std::lock_guard<std::mutex> lock(mutex_);
  statuses_.forged_heard += forged;
  statuses_.forged_verified += forged && ok;
  if (!ok) {
    ++statuses_.refused;
    return;
  }
  ++statuses_.verified;
  status_ = SolverStatusView{st.scene, st.method, st.refusals, st.updates, st.dropped_poses,
                             st.rejected_messages, st.epoch, Clock::now()};
}

void SessionWatch::OnShape(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  thread_shape_t shape;
  if (!messages::DecodeAndValidate(rbuf, &shape, nullptr)) return;
  const bool forged = shape.scene == kForgedMarker;
  const bool ok = VerifiedByServer(rbuf, channel);
  std::lock_guard<std::mutex> lock(mutex_);
  shapes_.forged_heard += forged;
  shapes_.forged_verified += forged && ok;
  ++(ok ? shapes_.verified : shapes_.refused);
}

void SessionWatch::OnDeviceStatus(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  device_status_t st;
  if (!messages::DecodeAndValidate(rbuf, &st, nullptr)) return;
  const bool forged = st.device_id == kForgedMarker;
  auth::PublicKey device_key{};
  std::copy(std::begin(st.device_public_key), std::end(st.device_public_key), device_key.begin());
  bool certified = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auth::PublicKey& key : server_keys_) {
      certified = certified || auth::VerifyDeviceCertificate(key, st.sender_name, st.key_expires, device_key,
                                                             st.device_certificate);
    }
  }
  const bool ok = certified && st.sender_role == 1 &&
                  auth::VerifySignature(rbuf->data, rbuf->data_size, channel, device_key);
  std::lock_guard<std::mutex> lock(mutex_);
  device_statuses_.forged_heard += forged;
  device_statuses_.forged_verified += forged && ok;
  if (!ok) {
    ++device_statuses_.refused;
    return;
  }
  ++device_statuses_.verified;
  devices_[st.sender_name].push_back(DeviceStatusView{st.models_received, st.models_rejected, st.fades,
                                                      st.ticks, st.force_norm_n, Clock::now()});
}

std::optional<SolverStatusView> SessionWatch::status() {
  std::lock_guard<std::mutex> lock(mutex_);
  return status_;
}

std::optional<DeviceStatusView> SessionWatch::device(const std::string& name) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = devices_.find(name);
  if (it == devices_.end() || it->second.empty()) return std::nullopt;
  return it->second.back();
}

std::vector<DeviceStatusView> SessionWatch::device_history(const std::string& name) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = devices_.find(name);
  return it == devices_.end() ? std::vector<DeviceStatusView>{} : it->second;
}

ChannelCounts SessionWatch::shapes() {
  std::lock_guard<std::mutex> lock(mutex_);
  return shapes_;
}
ChannelCounts SessionWatch::statuses() {
  std::lock_guard<std::mutex> lock(mutex_);
  return statuses_;
}
ChannelCounts SessionWatch::device_statuses() {
  std::lock_guard<std::mutex> lock(mutex_);
  return device_statuses_;
}

std::optional<SolverStatusView> SessionWatch::NextStatus(double timeout_s) {
  return NextAfter<SolverStatusView>(Clock::now(), timeout_s, [this] { return status(); });
}

std::optional<DeviceStatusView> SessionWatch::NextDevice(const std::string& name, double timeout_s) {
  return NextAfter<DeviceStatusView>(Clock::now(), timeout_s, [this, &name] { return device(name); });
}

}  // namespace snapthread::roles_test
