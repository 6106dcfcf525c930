// DeviceKeys: the device credential a device client tags and checks with, and the one it
// replaced while that one's grace lasts (docs/security.md, "Roles on the wire").
//
// A reload (SIGHUP) installs a new KeySet: poses and statuses are tagged with it from the
// next one on, while force models MACed under the previous key (answers to poses already
// sent, or a server that has not rotated yet) are accepted for the grace period, so a
// rotation never fades the force.
//
// Threading: Replace is called by one thread at a time (the main thread); current() and
// ForModel() from any thread, lock-free and allocation-free (atomic pointers). Every
// KeySet installed is kept until the DeviceKeys is destroyed, so a pointer a reader took
// never dangles (a reload is rare: a few hundred bytes each).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "auth/key_set.h"

namespace snapthread::device {

class DeviceKeys {
 public:
  // `keys` must be a device's (KeySet::FromCredential of a device credential, or
  // KeySet::ForRole(root, kDevice, name)); throws std::invalid_argument otherwise.
  DeviceKeys(auth::KeySet keys, int64_t grace_us);
  DeviceKeys(const DeviceKeys&) = delete;
  DeviceKeys& operator=(const DeviceKeys&) = delete;

  // Installs `next` at now_us (the clock the readers pass): the current set becomes the
  // previous one, accepted until now_us + grace. False with *error (nothing changed)
  // when `next` is not a device's or names another device.
  bool Replace(auth::KeySet next, int64_t now_us, std::string* error);

  // The set to tag with now.
  const auth::KeySet& current() const { return *current_.load(std::memory_order_acquire); }
  // The set whose MAC key made a message carrying `wire_key_id` (its key_id field): the
  // current one, or the previous one while its grace lasts at now_us; nullptr otherwise.
  const auth::KeySet* ForKeyId(int64_t wire_key_id, int64_t now_us) const;
  // The previous set while its grace lasts at now_us, else nullptr.
  const auth::KeySet* Previous(int64_t now_us) const;
  // The device's name (every set installed carries the same).
  const std::string& name() const { return name_; }
  int64_t grace_us() const { return grace_us_; }
  // How many sets were installed after the first.
  int reloads() const { return reloads_.load(); }

 private:
  static bool IsDeviceSet(const auth::KeySet& keys);

  const std::string name_;
  const int64_t grace_us_;
  std::mutex replace_mutex_;                         // Replace only
  std::vector<std::unique_ptr<auth::KeySet>> all_;   // never shrinks (see the header)
  std::atomic<const auth::KeySet*> current_{nullptr};
  std::atomic<const auth::KeySet*> previous_{nullptr};
  std::atomic<int64_t> previous_until_us_{0};
  std::atomic<int> reloads_{0};
};

}  // namespace snapthread::device
