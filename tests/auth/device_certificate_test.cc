// Device certificates (auth/device_certificate.h): the server's signature over a device's
// name, expiry and public key verifies, and any change to one of them, to the certificate
// or to the server key is refused.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string>

#include "auth/device_certificate.h"
#include "auth/role.h"
#include "auth/role_keys.h"

namespace snapthread::auth {
namespace device_certificate_test {

constexpr int64_t kExpiry = 1798761600;

class DeviceCertificateTest : public ::testing::Test {
 protected:
  SessionKey root_ = SessionKey::Generate();
  Signer server_ = DeriveServerSigner(root_);
  PublicKey device_pk_ = DeriveDeviceSigner(DeriveDeviceKey(root_, "left", kExpiry)).public_key();
  DeviceCertificateBytes cert_ = DeviceCertificate(server_, "left", kExpiry, device_pk_);
};

TEST_F(DeviceCertificateTest, AGenuineCertificateVerifies) {
  EXPECT_TRUE(VerifyDeviceCertificate(server_.public_key(), "left", kExpiry, device_pk_, cert_.data()));
  // Deterministic (Ed25519): the same inputs give the same certificate.
  EXPECT_EQ(DeviceCertificate(server_, "left", kExpiry, device_pk_), cert_);
  // Never-expiring and longest-name devices too.
  const std::string longest(kMaxRoleNameBytes, 'z');
  const DeviceCertificateBytes never = DeviceCertificate(server_, longest, kNeverExpires, device_pk_);
  EXPECT_TRUE(VerifyDeviceCertificate(server_.public_key(), longest, kNeverExpires, device_pk_, never.data()));
}

TEST_F(DeviceCertificateTest, AnyChangeIsRefused) {
  const PublicKey& server_pk = server_.public_key();
  EXPECT_FALSE(VerifyDeviceCertificate(server_pk, "right", kExpiry, device_pk_, cert_.data()));
  EXPECT_FALSE(VerifyDeviceCertificate(server_pk, "lef", kExpiry, device_pk_, cert_.data()));
  EXPECT_FALSE(VerifyDeviceCertificate(server_pk, "left0", kExpiry, device_pk_, cert_.data()));
  EXPECT_FALSE(VerifyDeviceCertificate(server_pk, "left", kExpiry + 1, device_pk_, cert_.data()));
  EXPECT_FALSE(VerifyDeviceCertificate(server_pk, "left", kNeverExpires, device_pk_, cert_.data()));
  // Every byte of the device key and of the certificate matters.
  for (std::size_t i = 0; i < device_pk_.size(); ++i) {
    PublicKey other = device_pk_;
    other[i] ^= 0x01;
    EXPECT_FALSE(VerifyDeviceCertificate(server_pk, "left", kExpiry, other, cert_.data())) << i;
  }
  for (std::size_t i = 0; i < cert_.size(); ++i) {
    DeviceCertificateBytes other = cert_;
    other[i] ^= 0x80;
    EXPECT_FALSE(VerifyDeviceCertificate(server_pk, "left", kExpiry, device_pk_, other.data())) << i;
  }
  // Another session's server, and another device's key of this session.
  const PublicKey other_server = DeriveServerPublicKey(SessionKey::Generate());
  EXPECT_FALSE(VerifyDeviceCertificate(other_server, "left", kExpiry, device_pk_, cert_.data()));
  const PublicKey right_pk = DeriveDeviceSigner(DeriveDeviceKey(root_, "right", kExpiry)).public_key();
  EXPECT_FALSE(VerifyDeviceCertificate(server_pk, "left", kExpiry, right_pk, cert_.data()));
  // A device's own signer cannot vouch for itself.
  const Signer device = DeriveDeviceSigner(DeriveDeviceKey(root_, "left", kExpiry));
  const DeviceCertificateBytes self = DeviceCertificate(device, "left", kExpiry, device_pk_);
  EXPECT_FALSE(VerifyDeviceCertificate(server_pk, "left", kExpiry, device_pk_, self.data()));
}

TEST_F(DeviceCertificateTest, InvalidNamesAndExpiriesAreRefused) {
  EXPECT_THROW(DeviceCertificate(server_, "", kExpiry, device_pk_), std::invalid_argument);
  EXPECT_THROW(DeviceCertificate(server_, std::string(kMaxRoleNameBytes + 1, 'a'), kExpiry, device_pk_),
               std::invalid_argument);
  EXPECT_THROW(DeviceCertificate(server_, std::string_view("a\0b", 3), kExpiry, device_pk_), std::invalid_argument);
  EXPECT_THROW(DeviceCertificate(server_, "left", -1, device_pk_), std::invalid_argument);
  const PublicKey& server_pk = server_.public_key();
  EXPECT_FALSE(VerifyDeviceCertificate(server_pk, "", kExpiry, device_pk_, cert_.data()));
  EXPECT_FALSE(VerifyDeviceCertificate(server_pk, std::string(1000, 'a'), kExpiry, device_pk_, cert_.data()));
  EXPECT_FALSE(VerifyDeviceCertificate(server_pk, std::string_view("left\0", 5), kExpiry, device_pk_, cert_.data()));
  EXPECT_FALSE(VerifyDeviceCertificate(server_pk, "left", -1, device_pk_, cert_.data()));
}

}  // namespace device_certificate_test
}  // namespace snapthread::auth
