// A device's certificate: the server's Ed25519 signature that vouches for the public key a
// device signs its statuses with (DeriveDeviceSigner of its device key), bound to the
// device's name and its credential's expiry. An observer, which holds only the server's
// public key, checks the certificate and then the device's signature, so it can show what
// a device publishes without holding anything a device or the server would accept.
//
//   certificate = Ed25519(server signer, "snapthread-device-cert-v1" || name || '\0' ||
//                         le64(expires_unix_s) || device_public_key)
//
// The name's grammar (auth/role.h) has no NUL, so the NUL keeps name and expiry apart; the
// expiry and the key have fixed widths.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "auth/key_id.h"
#include "auth/signature.h"

namespace snapthread::auth {

inline constexpr std::size_t kDeviceCertificateBytes = kSignatureBytes;
using DeviceCertificateBytes = std::array<uint8_t, kDeviceCertificateBytes>;

// The certificate of device `name` (a valid role name) expiring at `expires_unix_s`
// (kNeverExpires or a positive time) for `device_public_key`, signed by `server`. Throws
// std::invalid_argument for an invalid name or a negative expiry.
DeviceCertificateBytes DeviceCertificate(const Signer& server, std::string_view name, int64_t expires_unix_s,
                                         const PublicKey& device_public_key);

// Whether `certificate` is `server_public_key`'s certificate of exactly this name, expiry
// and device key. False for an invalid name or a negative expiry. Allocates nothing (the
// signed bytes are built on the stack): observers call it for each device status.
[[nodiscard]] bool VerifyDeviceCertificate(const PublicKey& server_public_key, std::string_view name,
                                           int64_t expires_unix_s, const PublicKey& device_public_key,
                                           const uint8_t certificate[kDeviceCertificateBytes]) noexcept;

}  // namespace snapthread::auth
