#include "server_keys.h"

#include <sys/stat.h>

#include <cmath>
#include <ctime>
#include <exception>
#include <utility>

#include <spdlog/spdlog.h>

#include "auth/key_file.h"
#include "auth/revocation_list.h"
#include "auth/role_keys.h"
#include "auth/sealed_message.h"

namespace snapthread::server {
namespace {

bool Exists(const std::string& path) {
  struct stat info {};
  return ::stat(path.c_str(), &info) == 0;
}

auth::SessionKey Copy(const auth::SessionKey& key) {
  return auth::SessionKey::FromBytes(key.data(), auth::SessionKey::kBytes);
}

auth::SessionKey LoadRootFile(const std::string& path) {
  return auth::LoadKey(auth::KeyLocation{path, "--key"});
}

}  // namespace

int64_t UnixSeconds() { return static_cast<int64_t>(std::time(nullptr)); }

ServerKeys::ServerKeys(std::string root_path, auth::SessionKey root, double grace_s, bool encrypt)
    : root_path_(std::move(root_path)),
      grace_s_(static_cast<int64_t>(std::ceil(grace_s))),
      ring_(Copy(root)),
      encrypt_(encrypt) {
  const std::string previous_path = root_path_ + ".previous";
  if (!root_path_.empty() && Exists(previous_path)) {
    // A server restarted during a rotation: devices still on the previous root are
    // accepted for the grace period, as the reload that found the rotation would have.
    auth::SessionKey previous = LoadRootFile(previous_path);
    if (previous.Id() != root.Id()) {
      ring_ = auth::KeyRing(Copy(previous));
      previous_until_unix_s_ = UnixSeconds() + grace_s_;
      ring_.Rotate(std::move(root), previous_until_unix_s_);
      spdlog::info("server: {} found: its key {} is accepted for {} s", previous_path, previous.Id(), grace_s_);
      previous_root_.emplace(std::move(previous));
    }
  }
  PublishSigners();
  ApplySealing(UnixSeconds());
  LoadRevocations(false);
}

void ServerKeys::ApplySealing(int64_t now_unix_s) {
  const bool in_grace = previous_root_.has_value() && now_unix_s < previous_until_unix_s_;
  const auth::SessionKey read = auth::DeriveReadKey(ring_.root());
  if (in_grace) {
    const auth::SessionKey previous_read = auth::DeriveReadKey(*previous_root_);
    auth::SetSealing(read, &previous_read, encrypt_, /*seal_with_previous=*/true);
  } else {
    auth::SetSealing(read, nullptr, encrypt_);
  }
  sealing_with_previous_ = in_grace;
}

void ServerKeys::PublishSigners() {
  auto set = std::make_unique<ServerSigners>(ServerSigners{auth::DeriveServerSigner(ring_.root()), {}, 0});
  if (previous_root_) {
    set->previous.emplace(auth::DeriveServerSigner(*previous_root_));
    set->previous_until_unix_s = previous_until_unix_s_;
  }
  signers_.store(set.get(), std::memory_order_release);
  signer_sets_.push_back(std::move(set));
}

void ServerKeys::LoadRevocations(bool keep_on_error) {
  if (root_path_.empty()) return;
  const std::string path = root_path_ + ".revoked";
  auth::RevocationList list;
  try {
    if (Exists(path)) list = auth::RevocationList::Load(path);
  } catch (const std::exception& e) {
    if (!keep_on_error) throw;
    spdlog::error("server: {} not reloaded, the previous {} revocation(s) stay: {}", path, revocations_,
                  e.what());
    return;
  }
  revocations_ = list.size();
  ring_.SetRevocations(std::move(list));
}

const DeviceKey* ServerKeys::DeviceKeyFor(std::string_view name, int64_t expires_unix_s,
                                          const auth::KeyId& key_id, const auth::SessionKey& key) {
  for (const auto& k : device_keys_) {
    if (k->key_id == key_id && k->expires_unix_s == expires_unix_s && k->name == name) return k.get();
  }
  if (device_keys_.size() >= kMaxDeviceKeys) return nullptr;
  device_keys_.push_back(
      std::make_unique<DeviceKey>(DeviceKey{std::string(name), expires_unix_s, key_id, Copy(key)}));
  return device_keys_.back().get();
}

void ServerKeys::Reload(int64_t now_unix_s) {
  try {
    auth::SessionKey fresh = LoadRootFile(root_path_);
    if (fresh.Id() != ring_.root().Id()) {
      previous_root_.emplace(Copy(ring_.root()));
      previous_until_unix_s_ = now_unix_s + grace_s_;
      ring_.Rotate(std::move(fresh), previous_until_unix_s_);
      PublishSigners();
      ApplySealing(now_unix_s);
    }
  } catch (const std::exception& e) {
    spdlog::error("server: reload: {} not read, key {} stays: {}", root_path_, ring_.root().Id(), e.what());
  }
  LoadRevocations(true);
  const int64_t grace_left = previous_root_ ? std::max<int64_t>(0, previous_until_unix_s_ - now_unix_s) : 0;
  spdlog::info("server: keys reloaded: key {}, previous key {} ({} s of grace left), {} revocation(s)",
               ring_.root().Id(), previous_root_ ? previous_root_->Id() : std::string("none"), grace_left,
               revocations_);
  reloads_.fetch_add(1, std::memory_order_release);
}

}  // namespace snapthread::server
