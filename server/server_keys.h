// The server's keys (docs/security.md, "Roles: the key hierarchy"): the root key of --key
// FILE in an auth::KeyRing (with FILE.previous during a rotation's grace period and the
// revocations of FILE.revoked), the signers the publisher tags with, and the device keys
// force models are MACed with.
//
// Threads: the receive thread owns the ring (Resolve, DeviceKeyFor, Reload). The solve
// thread only reads what is handed to it: signers() (an atomic pointer to an immutable
// set, replaced on reload) and the DeviceKey a pose carries through the inbox (immutable
// once made). Both live as long as the ServerKeys (a reload adds, never frees), so the
// hot paths take no lock and allocate nothing once every key was seen.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "auth/key_ring.h"
#include "auth/session_key.h"
#include "auth/signature.h"

namespace snapthread::server {

// What the server signs with: the current root's key and, until previous_until_unix_s
// (exclusive), the previous root's.
struct ServerSigners {
  auth::Signer current;
  std::optional<auth::Signer> previous;
  int64_t previous_until_unix_s = 0;
  // `previous` while its grace lasts at `now_unix_s`, else nullptr.
  const auth::Signer* PreviousAt(int64_t now_unix_s) const {
    return previous && now_unix_s < previous_until_unix_s ? &*previous : nullptr;
  }
};

// One device key a pose was accepted with: the force model answering it carries its MAC.
struct DeviceKey {
  std::string name;             // the device (sender_name)
  int64_t expires_unix_s = 0;   // its credential's expiry
  auth::KeyId key_id{};
  auth::SessionKey key;
};

class ServerKeys {
 public:
  // Distinct device keys kept (each credential seen once; a rotation adds one per device).
  static constexpr size_t kMaxDeviceKeys = 256;

  // `root` was loaded from `root_path`. When root_path.previous exists (a rotation whose
  // server restarted), its key is accepted for `grace_s` from now; root_path.revoked
  // (missing = none) is applied. Throws auth::KeyFileError / auth::RevocationListError
  // naming the file when one of them exists but cannot be used.
  // `encrypt`: seal what the server publishes (--encrypt; auth/sealed_message.h). Either
  // way the process opens envelopes sealed under the read key of either root.
  ServerKeys(std::string root_path, auth::SessionKey root, double grace_s, bool encrypt = false);
  ServerKeys(const ServerKeys&) = delete;
  ServerKeys& operator=(const ServerKeys&) = delete;

  // Receive thread.
  auth::ResolvedKey Resolve(auth::Role role, std::string_view name, int64_t expires_unix_s,
                            const auth::KeyId& key_id, int64_t now_unix_s) {
    return ring_.Resolve(role, name, expires_unix_s, key_id, now_unix_s);
  }
  // The kept copy of an accepted device key (made on its first use); nullptr when
  // kMaxDeviceKeys are kept already.
  const DeviceKey* DeviceKeyFor(std::string_view name, int64_t expires_unix_s,
                                const auth::KeyId& key_id, const auth::SessionKey& key);
  // Re-reads the root file (a new root: the current one is accepted for the grace period
  // from `now_unix_s`) and the revocation list (a broken list keeps the old one, logged
  // naming the file). Logs one line with both key ids and the number of revocations.
  void Reload(int64_t now_unix_s);
  // Between two receives: when a rotation's grace has ended, the server stops sealing with
  // the previous root's read key (receivers not reloaded by then no longer open it).
  void Tick(int64_t now_unix_s) {
    if (sealing_with_previous_ && now_unix_s >= previous_until_unix_s_) ApplySealing(now_unix_s);
  }

  // Any thread.
  const ServerSigners& signers() const { return *signers_.load(std::memory_order_acquire); }
  int64_t reloads() const { return reloads_.load(std::memory_order_acquire); }
  const std::string& root_path() const { return root_path_; }

 private:
  // The signers of the ring's roots, for the publisher.
  void PublishSigners();
  // The process's sealing keys (auth::SetSealing): the current root's read key, and during
  // a rotation's grace the previous one, which the server then seals with, so that
  // receivers that have not reloaded yet keep opening what it publishes.
  void ApplySealing(int64_t now_unix_s);
  // FILE.revoked (missing: none) into the ring. A broken list throws at start and, on a
  // reload (`keep_on_error`), keeps the old list with an error naming the file.
  void LoadRevocations(bool keep_on_error);

  std::string root_path_;
  int64_t grace_s_;
  auth::KeyRing ring_;
  std::optional<auth::SessionKey> previous_root_;  // during (and after) a rotation's grace
  int64_t previous_until_unix_s_ = 0;
  size_t revocations_ = 0;
  bool encrypt_ = false;
  bool sealing_with_previous_ = false;
  std::vector<std::unique_ptr<DeviceKey>> device_keys_;
  std::vector<std::unique_ptr<const ServerSigners>> signer_sets_;  // every set ever published
  std::atomic<const ServerSigners*> signers_{nullptr};
  std::atomic<int64_t> reloads_{0};
};

// Wall-clock seconds (what credential expiries and grace periods are measured in).
int64_t UnixSeconds();

}  // namespace snapthread::server
