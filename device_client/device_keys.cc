#include "device_keys.h"

#include <stdexcept>
#include <utility>

#include "auth/message_mac.h"
#include "auth/role.h"

namespace snapthread::device {

bool DeviceKeys::IsDeviceSet(const auth::KeySet& keys) {
  return keys.role() == auth::Role::kDevice && keys.mac_key() != nullptr &&
         keys.device_status_tagger() != nullptr && !keys.name().empty();
}

DeviceKeys::DeviceKeys(auth::KeySet keys, int64_t grace_us)
    : name_(keys.name()), grace_us_(grace_us) {
  if (!IsDeviceSet(keys)) throw std::invalid_argument("DeviceKeys: not a device's key set");
  if (grace_us < 0) throw std::invalid_argument("DeviceKeys: negative grace");
  all_.push_back(std::make_unique<auth::KeySet>(std::move(keys)));
  current_.store(all_.back().get(), std::memory_order_release);
}

bool DeviceKeys::Replace(auth::KeySet next, int64_t now_us, std::string* error) {
  if (!IsDeviceSet(next)) {
    *error = "not a device credential";
    return false;
  }
  if (next.name() != name_) {
    *error = "it is device '" + next.name() + "'s credential, this device is '" + name_ + "'";
    return false;
  }
  std::lock_guard<std::mutex> lock(replace_mutex_);
  all_.push_back(std::make_unique<auth::KeySet>(std::move(next)));
  // The previous slot first: a reader that sees the new current also sees its predecessor.
  previous_.store(current_.load(std::memory_order_relaxed), std::memory_order_relaxed);
  previous_until_us_.store(now_us + grace_us_, std::memory_order_relaxed);
  current_.store(all_.back().get(), std::memory_order_release);
  reloads_.fetch_add(1);
  return true;
}

const auth::KeySet* DeviceKeys::Previous(int64_t now_us) const {
  const auth::KeySet* cur = current_.load(std::memory_order_acquire);
  (void)cur;  // orders the loads below after the current one
  const auth::KeySet* prev = previous_.load(std::memory_order_relaxed);
  if (prev == nullptr || now_us >= previous_until_us_.load(std::memory_order_relaxed)) return nullptr;
  return prev;
}

const auth::KeySet* DeviceKeys::ForKeyId(int64_t wire_key_id, int64_t now_us) const {
  const auth::KeySet* cur = current_.load(std::memory_order_acquire);
  if (auth::KeyIdToWire(cur->tagger().key_id) == wire_key_id) return cur;
  const auth::KeySet* prev = Previous(now_us);
  if (prev != nullptr && auth::KeyIdToWire(prev->tagger().key_id) == wire_key_id) return prev;
  return nullptr;
}

}  // namespace snapthread::device
