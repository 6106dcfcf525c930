// A device's certificate: the server's Ed25519 signature over a device's name, its
// credential's expiry and the device's own public key (derived from its secret,
// DeriveDeviceSigner), so that an observer, holding only the server's public key, can
// verify what a device signs (its status) and who it is (docs/security.md).
//
//   certificate = Ed25519_server("snapthread-device-cert-v1" || name || 0 || le64(expiry) || device_pk)
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "auth/key_id.h"
#include "auth/signature.h"

namespace snapthread::auth {

using Certificate = std::array<uint8_t, kSignatureBytes>;

// Throws std::invalid_argument for a name outside IsValidRoleName.
Certificate DeviceCertificate(const Signer& server, std::string_view name, int64_t expires_unix_s,
                              const PublicKey& device_public_key);

// No allocation, never throws; false for an invalid name.
[[nodiscard]] bool VerifyDeviceCertificate(const PublicKey& server_public_key, std::string_view name,
                                           int64_t expires_unix_s, const PublicKey& device_public_key,
                                           const uint8_t certificate[kSignatureBytes]) noexcept;

}  // namespace snapthread::auth
