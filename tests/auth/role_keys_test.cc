// The roles' key hierarchy (auth/role_keys.h): derivations are deterministic and
// separated (every name, expiry, role and root gives another key), and an observer's
// credential holds nothing that MACs a pose, signs as the server or gives a master.
#include <gtest/gtest.h>
#include <sodium.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "auth/credential.h"
#include "auth/message_mac.h"
#include "auth/role_keys.h"
#include "auth/signature.h"
#include "sample_messages.h"

namespace snapthread::auth {
namespace role_keys_test {

std::string Bytes(const SessionKey& key) {
  return std::string(reinterpret_cast<const char*>(key.data()), SessionKey::kBytes);
}
std::string Bytes(const PublicKey& key) { return std::string(key.begin(), key.end()); }

// The root as fixed bytes, so a failure is reproducible.
// A device `name`'s tagger MACing with `key` (the genuine key or a forger's guess).
Tagger DeviceMac(const char* name, const SessionKey& key) {
  Tagger t;
  t.role = Role::kDevice;
  t.name = name;
  t.mac_key = &key;
  return t;
}

SessionKey FixedRoot(uint8_t fill) {
  uint8_t bytes[SessionKey::kBytes];
  for (std::size_t i = 0; i < sizeof bytes; ++i) bytes[i] = static_cast<uint8_t>(fill + 7 * i);
  return SessionKey::FromBytes(bytes, sizeof bytes);
}

TEST(RoleKeysTest, DerivationsAreDeterministic) {
  const SessionKey root = FixedRoot(1);
  const SessionKey same_root = FixedRoot(1);
  EXPECT_EQ(Bytes(DeriveDeviceKey(root, "left", 1798761600)), Bytes(DeriveDeviceKey(same_root, "left", 1798761600)));
  EXPECT_EQ(Bytes(DeriveOperatorKey(root, "alice", 0)), Bytes(DeriveOperatorKey(same_root, "alice", 0)));
  EXPECT_EQ(Bytes(DeriveReadKey(root)), Bytes(DeriveReadKey(same_root)));
  EXPECT_EQ(Bytes(DeriveServerPublicKey(root)), Bytes(DeriveServerPublicKey(same_root)));
  EXPECT_EQ(DeriveServerSigner(root).key_id(), SignatureVerifier(DeriveServerPublicKey(root)).key_id());
}

TEST(RoleKeysTest, EveryNameExpiryRoleAndRootGivesAnotherKey) {
  const SessionKey root = FixedRoot(1);
  const SessionKey other_root = FixedRoot(2);
  std::set<std::string> keys;
  std::size_t made = 0;
  auto add = [&](const SessionKey& key) {
    keys.insert(Bytes(key));
    ++made;
  };
  for (const SessionKey* r : {&root, &other_root}) {
    for (const char* name : {"left", "right", "lef", "left_", "a", "L"}) {
      for (const int64_t expiry : {int64_t{0}, int64_t{1}, int64_t{1798761600}, int64_t{1798761601}}) {
        add(DeriveDeviceKey(*r, name, expiry));
        add(DeriveOperatorKey(*r, name, expiry));
      }
    }
    add(DeriveReadKey(*r));
    add(DeriveDeviceSealKey(DeriveDeviceKey(*r, "left", 0)));
  }
  add(root);
  add(other_root);
  EXPECT_EQ(keys.size(), made);
  // The server's signing key differs between roots, and from every symmetric key.
  EXPECT_NE(Bytes(DeriveServerPublicKey(root)), Bytes(DeriveServerPublicKey(other_root)));
}

TEST(RoleKeysTest, InvalidNamesAndExpiriesAreRefused) {
  const SessionKey root = FixedRoot(1);
  for (const std::string& name : std::vector<std::string>{"", "left hand", "a/b", "ü", std::string(33, 'a'), std::string("a\0b", 3)}) {
    EXPECT_THROW(DeriveDeviceKey(root, name, 0), std::invalid_argument) << name;
  }
  EXPECT_NO_THROW(DeriveDeviceKey(root, std::string(32, 'a'), 0));
  EXPECT_THROW(DeriveDeviceKey(root, "left", -1), std::invalid_argument);
  EXPECT_THROW(DeriveRoleKey(root, Role::kObserver, "x", 0), std::invalid_argument);
}

TEST(RoleKeysTest, KeyIdsNameKeysWithoutShowingThemAndDependOnTheRole) {
  const SessionKey root = FixedRoot(1);
  const SessionKey device = DeriveDeviceKey(root, "left", 0);
  EXPECT_NE(SecretKeyId("device", device), SecretKeyId("operator", device));
  EXPECT_NE(SecretKeyId("device", device), SecretKeyId("device", DeriveDeviceKey(root, "right", 0)));
  const std::string id = KeyIdToHex(SecretKeyId("device", device));
  EXPECT_EQ(id.size(), 16u);
  EXPECT_EQ(Bytes(device).find(std::string(id.begin(), id.end())), std::string::npos);
  EXPECT_EQ(KeyIdToHex(RootKeyId(root)), root.Id());
  EXPECT_EQ(KeyIdFromHex(id), SecretKeyId("device", device));
  EXPECT_FALSE(KeyIdFromHex("0123456789abcde"));
  EXPECT_FALSE(KeyIdFromHex("0123456789abcdeg"));
  EXPECT_FALSE(KeyIdFromHex(" 0123456789abcde"));
}

// Everything an observer can compute from its credential: the credential's bytes, and
// hashes of each of its fields, used as keys and as signing seeds.
std::vector<std::string> ObserverDerivables(const Credential& observer) {
  std::vector<std::string> out = {Bytes(*observer.read_key), Bytes(observer.server_public_key)};
  const std::size_t n = out.size();
  for (std::size_t i = 0; i < n; ++i) {
    uint8_t h[32];
    crypto_generichash(h, sizeof h, reinterpret_cast<const uint8_t*>(out[i].data()), out[i].size(), nullptr, 0);
    out.emplace_back(reinterpret_cast<const char*>(h), sizeof h);
  }
  return out;
}

TEST(RoleKeysTest, AnObserverCredentialHoldsNoSecretThatSignsOrMacs) {
  const SessionKey root = FixedRoot(3);
  const Credential observer = IssueCredential(root, Role::kObserver, "", 0);
  const std::string text = FormatCredential(observer);
  // Not one derived secret appears in the credential, raw or in hex.
  uint8_t seed[32];
  crypto_kdf_derive_from_key(seed, sizeof seed, 1, kKdfContext, root.data());
  std::vector<std::string> secrets = {Bytes(root), std::string(reinterpret_cast<char*>(seed), 32)};
  for (const uint64_t id : {2u, 4u}) {
    uint8_t master[32];
    crypto_kdf_derive_from_key(master, sizeof master, id, kKdfContext, root.data());
    secrets.emplace_back(reinterpret_cast<char*>(master), 32);
  }
  secrets.push_back(Bytes(DeriveDeviceKey(root, "left", 0)));
  secrets.push_back(Bytes(DeriveOperatorKey(root, "alice", 0)));
  for (const std::string& s : secrets) {
    EXPECT_EQ(text.find(s), std::string::npos);
    EXPECT_EQ(text.find(ToHex(reinterpret_cast<const uint8_t*>(s.data()), s.size())), std::string::npos);
    EXPECT_EQ(text.find(ToHex(reinterpret_cast<const uint8_t*>(s.data()), 8)), std::string::npos);
  }
  // Nothing derivable from it signs as the server or MACs a pose the server accepts.
  const SignatureVerifier server(observer.server_public_key);
  const SessionKey device_key = DeriveDeviceKey(root, "left", 0);
  device_state_t pose = test_support::Sample<device_state_t>();
  const uint8_t payload[] = "force model";
  for (const std::string& d : ObserverDerivables(observer)) {
    ASSERT_EQ(d.size(), 32u);
    const Signer forger = Signer::FromSeed(reinterpret_cast<const uint8_t*>(d.data()));
    uint8_t signature[kSignatureBytes];
    forger.Sign(payload, sizeof payload, signature);
    EXPECT_FALSE(server.Verify(payload, sizeof payload, signature));
    const SessionKey forged_key = SessionKey::FromBytes(reinterpret_cast<const uint8_t*>(d.data()), 32);
    ASSERT_TRUE(Sign(&pose, "SNAPTHREAD_DEVICE_STATE", 1, 1, DeviceMac("left", forged_key)));
    std::vector<uint8_t> bytes(static_cast<std::size_t>(pose.getEncodedSize()));
    pose.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), "SNAPTHREAD_DEVICE_STATE", device_key));
  }
  // ... while the genuine device key does.
  ASSERT_TRUE(Sign(&pose, "SNAPTHREAD_DEVICE_STATE", 1, 1, DeviceMac("left", device_key)));
  std::vector<uint8_t> bytes(static_cast<std::size_t>(pose.getEncodedSize()));
  pose.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  EXPECT_TRUE(VerifyMac(bytes.data(), bytes.size(), "SNAPTHREAD_DEVICE_STATE", device_key));
}

TEST(RoleKeysTest, OneDevicesKeyDoesNotDriveAnotherGrasp) {
  const SessionKey root = FixedRoot(4);
  const SessionKey left = DeriveDeviceKey(root, "left", 0);
  const SessionKey right = DeriveDeviceKey(root, "right", 0);
  device_state_t pose = test_support::Sample<device_state_t>();
  ASSERT_TRUE(Sign(&pose, "SNAPTHREAD_DEVICE_STATE_right", 1, 1, DeviceMac("left", left)));
  std::vector<uint8_t> bytes(static_cast<std::size_t>(pose.getEncodedSize()));
  pose.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), "SNAPTHREAD_DEVICE_STATE_right", right));
  EXPECT_TRUE(VerifyMac(bytes.data(), bytes.size(), "SNAPTHREAD_DEVICE_STATE_right", left));
}

TEST(RoleKeysTest, ADevicesSignerIsItsOwnAndReDerivableByTheServer) {
  const SessionKey root = FixedRoot(5);
  const Signer left = DeriveDeviceSigner(DeriveDeviceKey(root, "left", 0));
  const Signer again = DeriveDeviceSigner(DeriveDeviceKey(root, "left", 0));
  EXPECT_EQ(left.public_key(), again.public_key());
  EXPECT_NE(left.public_key(), DeriveDeviceSigner(DeriveDeviceKey(root, "right", 0)).public_key());
  EXPECT_NE(left.public_key(), DeriveServerPublicKey(root));
}

}  // namespace role_keys_test
}  // namespace snapthread::auth
