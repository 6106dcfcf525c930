// The roles' per-message work allocates nothing with caller buffers (the device's 1 kHz
// path and the server's receive thread): Ed25519 sign and verify, AEAD seal and open, a
// key ring lookup after the first, a revocation check.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "allocation_counter.h"
#include "auth/aead.h"
#include "auth/key_ring.h"
#include "auth/revocation_list.h"
#include "auth/role_keys.h"
#include "auth/signature.h"

namespace snapthread::auth {
namespace role_alloc_test {

using test_support::AllocationCounter;

TEST(RoleAllocationTest, SignVerifySealOpenAndLookupsNeverAllocate) {
  const SessionKey root = SessionKey::Generate();
  const Signer signer = DeriveServerSigner(root);
  const SignatureVerifier verifier(signer.public_key());
  const SessionKey read_key = DeriveReadKey(root);
  KeyRing ring(SessionKey::FromBytes(root.data(), SessionKey::kBytes));
  ring.SetRevocations(RevocationList::Parse("device right\n", "test"));
  const KeyId left = SecretKeyId("device", DeriveDeviceKey(root, "left", 0));
  ASSERT_EQ(ring.Resolve(Role::kDevice, "left", 0, left, 1).verdict, KeyVerdict::kAccepted);  // warm-up

  std::vector<uint8_t> message(200, 0x5a), sealed(200 + kAeadOverheadBytes), plain(200);
  const uint8_t ad[] = "SNAPTHREAD_FORCE_MODEL";
  uint8_t sig[kSignatureBytes];
  long allocations = 0;
  int verified = 0, opened = 0, accepted = 0, revoked = 0;
  for (int i = 0; i < 1000; ++i) {
    message[i % message.size()] = static_cast<uint8_t>(i);
    AllocationCounter counter;
    signer.Sign(message.data(), message.size(), sig);
    if (i % 10 == 3) sig[5] ^= 1;  // now and then a forged one
    verified += verifier.Verify(message.data(), message.size(), sig) ? 1 : 0;
    std::size_t n = 0, m = 0;
    if (!Seal(read_key, {message.data(), message.size()}, {ad, sizeof ad}, sealed.data(), sealed.size(), &n)) break;
    if (i % 10 == 7) sealed[40] ^= 1;
    opened += Open(read_key, {sealed.data(), n}, {ad, sizeof ad}, plain.data(), plain.size(), &m) ? 1 : 0;
    accepted += ring.Resolve(Role::kDevice, "left", 0, left, 1).verdict == KeyVerdict::kAccepted ? 1 : 0;
    revoked += ring.Resolve(Role::kDevice, "right", 0, left, 1).verdict == KeyVerdict::kRevoked ? 1 : 0;
    allocations += counter.mallocs();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(verified, 900);
  EXPECT_EQ(opened, 900);
  EXPECT_EQ(accepted, 1000);
  EXPECT_EQ(revoked, 1000);
}

TEST(RoleAllocationTest, TheCounterSeesAFirstLookup) {
  // The guard can fail on this path: a key ring's first lookup of a key caches it, with
  // its name (a heap string beyond the small-string buffer; the key itself is in
  // sodium_malloc's mapped pages, which malloc does not see).
  const SessionKey root = SessionKey::Generate();
  KeyRing ring(SessionKey::FromBytes(root.data(), SessionKey::kBytes));
  const std::string name = "left_hand_of_the_surgeon";
  const KeyId left = SecretKeyId("device", DeriveDeviceKey(root, name, 0));
  AllocationCounter counter;
  EXPECT_EQ(ring.Resolve(Role::kDevice, name, 0, left, 1).verdict, KeyVerdict::kAccepted);
  EXPECT_GE(counter.mallocs(), 1);
}

}  // namespace role_alloc_test
}  // namespace snapthread::auth
