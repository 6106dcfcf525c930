#include "server.h"

#include <chrono>
#include <stdexcept>
#include <utility>

#include <spdlog/spdlog.h>

#include "auth/key_set.h"
#include "auth/session_epoch.h"
#include "lcm_server_transport.h"
#include "messages/lcm_url.h"
#include "scene_dir.h"

namespace snapthread::server {
namespace {

constexpr int kReceiveTimeoutMs = 50;  // how long Stop() may wait for the receive thread

// The root key of --key: made first with --create-key when missing. A credential file is
// refused naming the root key as what the server needs (auth::LoadKeySet).
auth::SessionKey LoadServerKey(const auth::KeyLocation& where, bool create, bool* created) {
  if (create && !auth::LooksLikeCredential(where.path)) {
    auth::LoadedKey loaded = auth::LoadOrCreateKey(where);
    *created = loaded.created;
    return std::move(loaded.key);
  }
  const auth::KeySet keys = auth::LoadKeySet(where, auth::Role::kServer, "snapthread-server");
  if (keys.root() == nullptr) {
    throw auth::KeyFileError(where.path + " is not the session's root key, which snapthread-server needs");
  }
  return auth::SessionKey::FromBytes(keys.root()->data(), auth::SessionKey::kBytes);
}

std::unique_ptr<ServerTransport> OwnLcmTransport(const ServerParams& params) {
  const std::string url = messages::WithReceiveBuffer(messages::ResolveLcmUrl(params.lcm_url),
                                                      messages::kServiceBufferBytes);
  return std::make_unique<LcmServerTransport>(url, params.session);
}

}  // namespace

Server::Server(const ServerParams& params, ServerTestHooks hooks)
    : Server(params, nullptr, OwnLcmTransport, std::move(hooks)) {}

Server::Server(const ServerParams& params, ServerTransport* transport, ServerTestHooks hooks)
    : Server(params, transport, TransportMaker(), std::move(hooks)) {}

Server::Server(const ServerParams& params, ServerTransport* transport,
               TransportMaker make_transport, ServerTestHooks hooks)
    : params_(params),
      key_location_(auth::ResolveKeyPath(params.key_path)),
      key_(LoadServerKey(key_location_, params.create_key, &key_created_)),
      epoch_(auth::NewEpoch()) {
  std::string error;
  if (!params_.IsValid(&error)) throw std::invalid_argument(error);
  keys_ = std::make_unique<ServerKeys>(key_location_.path,
                                       auth::SessionKey::FromBytes(key_.data(), auth::SessionKey::kBytes),
                                       params_.key_grace_s, params_.encrypt);
  channels_ = messages::Channels(params_.session);
  if (params_.scene_dir.empty()) params_.scene_dir = DefaultSceneDir();
  solve_loop_ = std::make_unique<SolveLoop>(params_, channels_, key_, epoch_, std::move(hooks),
                                            &counters_, &info_);
  if (make_transport) owned_transport_ = make_transport(params_);
  transport_ = owned_transport_ ? owned_transport_.get() : transport;
  if (transport_ == nullptr) throw std::invalid_argument("the server needs a transport");
  gate_ = std::make_unique<InboundGate>(channels_, keys_.get(), epoch_, &inbox_, &counters_);
  publisher_ = std::make_unique<Publisher>(transport_, channels_, keys_.get(), epoch_, &counters_);
}

Server::~Server() { Stop(); }

void Server::Start() {
  if (started_) return;
  started_ = true;
  const std::string serving = solve_loop_->Describe();  // before the solve thread owns it
  running_ = true;
  solve_thread_ = std::thread([this] { solve_loop_->Run(&inbox_, publisher_.get()); });
  receive_thread_ = std::thread([this] { ReceiveLoop(); });
  spdlog::info("server: session {} on {}, {}", channels_.session, transport_->Describe(), serving);
  spdlog::info("server: {} root key {} ({}), key id {}, epoch {:016x}",
               key_created_ ? "created a new" : "using the", key_location_.path,
               key_location_.origin, key_.Id(), static_cast<uint64_t>(epoch_));
  if (key_created_) {
    spdlog::info("server: keep {} on this host only; issue each machine its role's credential "
                 "(snapthread-keygen --role ROLE --key {} --out FILE)", key_location_.path, key_location_.path);
  }
}

void Server::Stop() {
  if (!started_ || !running_.exchange(false)) return;
  stop_ = true;
  inbox_.RequestStop();
  if (receive_thread_.joinable()) receive_thread_.join();
  if (solve_thread_.joinable()) solve_thread_.join();
  solve_loop_->Finish();
}

void Server::RequestReload() { reload_requested_.store(true, std::memory_order_release); }

int64_t Server::key_reloads() const { return keys_->reloads(); }

void Server::ReceiveLoop() {
  while (!stop_.load()) {
    // A reload is applied here, between two receives: the ring belongs to this thread.
    if (reload_requested_.exchange(false, std::memory_order_acq_rel)) keys_->Reload(UnixSeconds());
    keys_->Tick(UnixSeconds());
    if (transport_->Receive(kReceiveTimeoutMs, gate_.get()) < 0) {
      // A transport error (socket gone): do not spin on it.
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
}

ServerStats Server::Stats() const {
  ServerStats s;
  counters_.CopyTo(&s);
  info_.CopyTo(&s, !params_.state_dir.empty());
  solve_loop_->CopyCheckpointStats(&s);
  return s;
}

}  // namespace snapthread::server
