#include "auth/device_certificate.h"

#include <cstring>
#include <stdexcept>
#include <string>

#include "auth/role.h"

namespace snapthread::auth {
namespace {

constexpr std::string_view kLabel = "snapthread-device-cert-v1";
// label || name || '\0' || le64(expiry) || public key, for the longest valid name.
constexpr std::size_t kMaxSignedBytes = kLabel.size() + kMaxRoleNameBytes + 1 + 8 + kPublicKeyBytes;

// The signed bytes into `out` (kMaxSignedBytes); their length, or 0 for an invalid name
// or a negative expiry.
std::size_t SignedBytes(std::string_view name, int64_t expires_unix_s, const PublicKey& device_public_key,
                        uint8_t out[kMaxSignedBytes]) noexcept {
  if (!IsValidRoleName(name) || expires_unix_s < 0) return 0;
  std::size_t at = 0;
  std::memcpy(out + at, kLabel.data(), kLabel.size());
  at += kLabel.size();
  std::memcpy(out + at, name.data(), name.size());
  at += name.size();
  out[at++] = 0;
  for (int i = 0; i < 8; ++i) out[at++] = static_cast<uint8_t>(static_cast<uint64_t>(expires_unix_s) >> (8 * i));
  std::memcpy(out + at, device_public_key.data(), device_public_key.size());
  return at + device_public_key.size();
}

}  // namespace

DeviceCertificateBytes DeviceCertificate(const Signer& server, std::string_view name, int64_t expires_unix_s,
                                         const PublicKey& device_public_key) {
  uint8_t bytes[kMaxSignedBytes];
  const std::size_t size = SignedBytes(name, expires_unix_s, device_public_key, bytes);
  if (size == 0) {
    throw std::invalid_argument("no device certificate for name '" + std::string(name) + "' and expiry " +
                                std::to_string(expires_unix_s) +
                                " (a name is 1 to 32 of A-Z a-z 0-9 _ -, an expiry 0 or positive)");
  }
  DeviceCertificateBytes certificate{};
  server.Sign(bytes, size, certificate.data());
  return certificate;
}

bool VerifyDeviceCertificate(const PublicKey& server_public_key, std::string_view name, int64_t expires_unix_s,
                             const PublicKey& device_public_key,
                             const uint8_t certificate[kDeviceCertificateBytes]) noexcept {
  uint8_t bytes[kMaxSignedBytes];
  const std::size_t size = SignedBytes(name, expires_unix_s, device_public_key, bytes);
  if (size == 0) return false;
  return SignatureVerifier(server_public_key).Verify(bytes, size, certificate);
}

}  // namespace snapthread::auth
