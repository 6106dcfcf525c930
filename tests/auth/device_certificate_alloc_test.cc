// VerifyDeviceCertificate allocates nothing: observers check a device's certificate for
// every status they show (auth/device_certificate.h builds the signed bytes on the stack).
#include <gtest/gtest.h>

#include <string>

#include "allocation_counter.h"
#include "auth/device_certificate.h"
#include "auth/role_keys.h"

namespace snapthread::auth {
namespace device_certificate_alloc_test {

using test_support::AllocationCounter;

TEST(DeviceCertificateAllocationTest, VerifyingNeverAllocates) {
  const SessionKey root = SessionKey::Generate();
  const Signer server = DeriveServerSigner(root);
  const std::string name(kMaxRoleNameBytes, 'd');  // the longest name: the whole stack buffer
  const std::string too_long(kMaxRoleNameBytes + 8, 'd');  // refused before any copy
  const PublicKey device_pk = DeriveDeviceSigner(DeriveDeviceKey(root, name, 0)).public_key();
  DeviceCertificateBytes cert = DeviceCertificate(server, name, 0, device_pk);
  long allocations = 0;
  int verified = 0;
  for (int i = 0; i < 200; ++i) {
    if (i % 10 == 3) cert[7] ^= 1;  // now and then a forged one
    AllocationCounter counter;
    verified += VerifyDeviceCertificate(server.public_key(), name, 0, device_pk, cert.data()) ? 1 : 0;
    verified += VerifyDeviceCertificate(server.public_key(), too_long, 0, device_pk,
                                        cert.data())
                    ? 1
                    : 0;  // invalid on purpose: never verifies
    allocations += counter.mallocs();
    if (i % 10 == 3) cert[7] ^= 1;
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(verified, 180);
}

}  // namespace device_certificate_alloc_test
}  // namespace snapthread::auth
