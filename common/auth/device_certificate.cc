#include "auth/device_certificate.h"

#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <string>

#include "auth/role.h"

namespace snapthread::auth {

namespace {

constexpr std::string_view kDomain = "snapthread-device-cert-v1";
constexpr std::size_t kMaxBytes = kDomain.size() + kMaxRoleNameBytes + 1 + 8 + kPublicKeyBytes;

// The signed bytes into `out` (kMaxBytes); their length, 0 for an invalid name.
std::size_t Encode(std::string_view name, int64_t expires_unix_s, const PublicKey& device_public_key,
                   uint8_t* out) noexcept {
  if (!IsValidRoleName(name)) return 0;
  uint8_t* p = out;
  std::memcpy(p, kDomain.data(), kDomain.size());
  p += kDomain.size();
  std::memcpy(p, name.data(), name.size());
  p += name.size();
  *p++ = 0;
  const auto e = static_cast<uint64_t>(expires_unix_s);
  for (int i = 0; i < 8; ++i) *p++ = static_cast<uint8_t>(e >> (8 * i));
  std::memcpy(p, device_public_key.data(), kPublicKeyBytes);
  p += kPublicKeyBytes;
  return static_cast<std::size_t>(p - out);
}

}  // namespace

Certificate DeviceCertificate(const Signer& server, std::string_view name, int64_t expires_unix_s,
                              const PublicKey& device_public_key) {
  uint8_t bytes[kMaxBytes];
  const std::size_t n = Encode(name, expires_unix_s, device_public_key, bytes);
  if (n == 0) throw std::invalid_argument("'" + std::string(name) + "' is not a valid device name");
  Certificate cert{};
  server.Sign(bytes, n, cert.data());
  return cert;
}

bool VerifyDeviceCertificate(const PublicKey& server_public_key, std::string_view name,
                             int64_t expires_unix_s, const PublicKey& device_public_key,
                             const uint8_t certificate[kSignatureBytes]) noexcept {
  uint8_t bytes[kMaxBytes];
  const std::size_t n = Encode(name, expires_unix_s, device_public_key, bytes);
  if (n == 0) return false;
  return SignatureVerifier(server_public_key).Verify(bytes, n, certificate);
}

}  // namespace snapthread::auth
