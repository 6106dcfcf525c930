// Ed25519 signatures (auth/signature.h) and sealed payloads (auth/aead.h): round trips,
// and every flipped bit, another key or other associated data refused.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "auth/aead.h"
#include "auth/role_keys.h"
#include "auth/signature.h"

namespace snapthread::auth {
namespace signature_aead_test {

std::vector<uint8_t> Message(std::size_t n) {
  std::vector<uint8_t> m(n);
  for (std::size_t i = 0; i < n; ++i) m[i] = static_cast<uint8_t>(31 * i + 7);
  return m;
}

TEST(SignatureTest, RoundTripAndEveryFlippedBitFails) {
  const SessionKey root = SessionKey::Generate();
  const Signer signer = DeriveServerSigner(root);
  const SignatureVerifier verifier(DeriveServerPublicKey(root));
  EXPECT_EQ(signer.key_id(), verifier.key_id());
  std::vector<uint8_t> m = Message(200);
  uint8_t sig[kSignatureBytes];
  signer.Sign(m.data(), m.size(), sig);
  ASSERT_TRUE(verifier.Verify(m.data(), m.size(), sig));
  for (std::size_t bit = 0; bit < 8 * m.size(); ++bit) {
    m[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
    EXPECT_FALSE(verifier.Verify(m.data(), m.size(), sig)) << "message bit " << bit;
    m[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
  }
  for (std::size_t bit = 0; bit < 8 * kSignatureBytes; ++bit) {
    sig[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
    EXPECT_FALSE(verifier.Verify(m.data(), m.size(), sig)) << "signature bit " << bit;
    sig[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
  }
  EXPECT_FALSE(verifier.Verify(m.data(), m.size() - 1, sig));
  // Another root's server key does not verify it.
  EXPECT_FALSE(SignatureVerifier(DeriveServerPublicKey(SessionKey::Generate())).Verify(m.data(), m.size(), sig));
  EXPECT_TRUE(verifier.Verify(m.data(), m.size(), sig));
}

TEST(AeadTest, RoundTripWithAssociatedData) {
  const SessionKey key = DeriveReadKey(SessionKey::Generate());
  const std::vector<uint8_t> m = Message(200);
  const std::string ad = "SNAPTHREAD_FORCE_MODEL";
  std::vector<uint8_t> sealed(m.size() + kAeadOverheadBytes);
  std::size_t sealed_size = 0;
  ASSERT_TRUE(Seal(key, {m.data(), m.size()}, {reinterpret_cast<const uint8_t*>(ad.data()), ad.size()},
                   sealed.data(), sealed.size(), &sealed_size));
  ASSERT_EQ(sealed_size, m.size() + kAeadOverheadBytes);
  // The plaintext does not appear in the sealed bytes.
  EXPECT_EQ(std::search(sealed.begin(), sealed.end(), m.begin(), m.begin() + 16), sealed.end());
  std::vector<uint8_t> plain(m.size());
  std::size_t plain_size = 0;
  ASSERT_TRUE(Open(key, {sealed.data(), sealed_size}, {reinterpret_cast<const uint8_t*>(ad.data()), ad.size()},
                   plain.data(), plain.size(), &plain_size));
  EXPECT_EQ(plain_size, m.size());
  EXPECT_EQ(plain, m);
  // Two seals of the same message differ (random nonce).
  std::vector<uint8_t> again(sealed.size());
  std::size_t again_size = 0;
  ASSERT_TRUE(Seal(key, {m.data(), m.size()}, {reinterpret_cast<const uint8_t*>(ad.data()), ad.size()},
                   again.data(), again.size(), &again_size));
  EXPECT_NE(again, sealed);
  // An empty message seals to the overhead alone.
  ASSERT_TRUE(Seal(key, {nullptr, 0}, {nullptr, 0}, again.data(), again.size(), &again_size));
  EXPECT_EQ(again_size, kAeadOverheadBytes);
  ASSERT_TRUE(Open(key, {again.data(), again_size}, {nullptr, 0}, plain.data(), plain.size(), &plain_size));
  EXPECT_EQ(plain_size, 0u);
}

TEST(AeadTest, FlippedBitsWrongKeyOrAssociatedDataFail) {
  const SessionKey key = DeriveDeviceSealKey(DeriveDeviceKey(SessionKey::Generate(), "left", 0));
  const std::vector<uint8_t> m = Message(200);
  const std::string ad = "SNAPTHREAD_DEVICE_STATE_left";
  const ByteView adv{reinterpret_cast<const uint8_t*>(ad.data()), ad.size()};
  std::vector<uint8_t> sealed(m.size() + kAeadOverheadBytes);
  std::size_t n = 0;
  ASSERT_TRUE(Seal(key, {m.data(), m.size()}, adv, sealed.data(), sealed.size(), &n));
  std::vector<uint8_t> plain(m.size());
  std::size_t plain_size = 1;
  for (std::size_t bit = 0; bit < 8 * n; ++bit) {
    sealed[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
    EXPECT_FALSE(Open(key, {sealed.data(), n}, adv, plain.data(), plain.size(), &plain_size)) << "bit " << bit;
    EXPECT_EQ(plain_size, 0u);
    sealed[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
  }
  const std::string other_ad = "SNAPTHREAD_DEVICE_STATE_right";
  EXPECT_FALSE(Open(key, {sealed.data(), n}, {reinterpret_cast<const uint8_t*>(other_ad.data()), other_ad.size()},
                    plain.data(), plain.size(), &plain_size));
  EXPECT_FALSE(Open(key, {sealed.data(), n}, {nullptr, 0}, plain.data(), plain.size(), &plain_size));
  EXPECT_FALSE(Open(DeriveReadKey(SessionKey::Generate()), {sealed.data(), n}, adv, plain.data(), plain.size(),
                    &plain_size));
  EXPECT_FALSE(Open(key, {sealed.data(), n - 1}, adv, plain.data(), plain.size(), &plain_size));
  EXPECT_FALSE(Open(key, {sealed.data(), kAeadOverheadBytes - 1}, adv, plain.data(), plain.size(), &plain_size));
  // Buffers too small are refused, not overrun.
  EXPECT_FALSE(Open(key, {sealed.data(), n}, adv, plain.data(), plain.size() - 1, &plain_size));
  std::size_t out = 7;
  EXPECT_FALSE(Seal(key, {m.data(), m.size()}, adv, sealed.data(), m.size() + kAeadOverheadBytes - 1, &out));
  EXPECT_EQ(out, 0u);
  EXPECT_TRUE(Open(key, {sealed.data(), n}, adv, plain.data(), plain.size(), &plain_size));
  EXPECT_EQ(plain, m);
}

}  // namespace signature_aead_test
}  // namespace snapthread::auth
