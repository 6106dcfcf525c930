#include "observer_check.h"

#include <algorithm>
#include <cstring>

#include "auth/device_certificate.h"
#include "auth/message_mac.h"
#include "auth/role.h"

namespace snapthread::viewer {

bool SignaturesAbsent(const void* data, std::size_t size) {
  if (data == nullptr || size < auth::kTagBytes) return false;
  const auto* sigs = static_cast<const uint8_t*>(data) + size - auth::kTagBytes;
  return std::all_of(sigs, sigs + 2 * auth::kSignatureBytes, [](uint8_t b) { return b == 0; });
}

ObserverVerdict CheckServerSigned(const void* data, std::size_t size, std::string_view channel,
                                  int8_t sender_role, const auth::PublicKey& server_key) {
  if (SignaturesAbsent(data, size)) return ObserverVerdict::kUnsigned;
  if (sender_role != static_cast<int8_t>(auth::Role::kServer)) return ObserverVerdict::kRefused;
  return auth::VerifySignature(data, size, channel, server_key) ? ObserverVerdict::kAccepted
                                                                : ObserverVerdict::kRefused;
}

ObserverVerdict CheckDeviceStatus(const void* data, std::size_t size, std::string_view channel,
                                  const device_status_t& decoded, const auth::PublicKey& server_key) {
  if (decoded.sender_role != static_cast<int8_t>(auth::Role::kDevice)) return ObserverVerdict::kRefused;
  auth::PublicKey device_key;
  std::memcpy(device_key.data(), decoded.device_public_key, device_key.size());
  if (!auth::VerifyDeviceCertificate(server_key, decoded.sender_name, decoded.key_expires, device_key,
                                     decoded.device_certificate)) {
    return ObserverVerdict::kRefused;
  }
  return auth::VerifySignature(data, size, channel, device_key) ? ObserverVerdict::kAccepted
                                                                : ObserverVerdict::kRefused;
}

}  // namespace snapthread::viewer
