// The server's side of the roles: the revocation list (auth/revocation_list.h) and the
// key ring (auth/key_ring.h) that re-derives a sender's key from its claimed name and
// expiry, under the current root or, during a grace period, the previous one.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "auth/credential.h"
#include "auth/key_ring.h"
#include "auth/revocation_list.h"
#include "auth/role_keys.h"

namespace snapthread::auth {
namespace key_ring_test {

namespace fs = std::filesystem;

std::string ListError(const std::string& text) {
  try {
    RevocationList::Parse(text, "/srv/revoked");
  } catch (const RevocationListError& e) {
    return e.what();
  }
  return "";
}

TEST(RevocationListTest, NamesAndKeyIdsAreRevoked) {
  const RevocationList list = RevocationList::Parse(
      "# lost in the lab, 2026-11-27\n\ndevice left\noperator alice\nkey_id 0123456789ABCDEF\ndevice left\n",
      "/srv/revoked");
  EXPECT_EQ(list.size(), 3u);
  const KeyId any{};
  const KeyId listed = *KeyIdFromHex("0123456789abcdef");
  EXPECT_TRUE(list.IsRevoked(Role::kDevice, "left", any));
  EXPECT_FALSE(list.IsRevoked(Role::kDevice, "right", any));
  EXPECT_FALSE(list.IsRevoked(Role::kOperator, "left", any));  // names are per role
  EXPECT_TRUE(list.IsRevoked(Role::kOperator, "alice", any));
  EXPECT_FALSE(list.IsRevoked(Role::kDevice, "alice", any));
  EXPECT_TRUE(list.IsRevoked(Role::kDevice, "right", listed));
  EXPECT_FALSE(RevocationList().IsRevoked(Role::kDevice, "left", listed));
  EXPECT_EQ(RevocationList::Parse("", "x").size(), 0u);
  EXPECT_EQ(RevocationList::Parse("device right", "x").size(), 1u);  // no final newline
}

TEST(RevocationListTest, MalformedLinesAreRefusedWithFileLineAndFix) {
  const std::pair<std::string, std::string> cases[] = {
      {"device left\nrobot arm\n", "line 2: unknown word"},
      {"observer viewer\n", "line 1: unknown word"},
      {"server host\n", "line 1: unknown word"},
      {"device le/ft\n", "line 1: a name is 1 to 32"},
      {"key_id 0123\n", "line 1: a key id is 16 hex digits"},
      {"key_id 0123456789abcdeg\n", "line 1: a key id is 16 hex digits"},
      {"device\n", "line 1: expected a word and one value"},
      {"device left right\n", "line 1: expected a word and one value"},
      {"\ndevice left\r\n", "line 2: the line ends with a carriage return"},
      {" device left\n", "line 1: expected a word and one value"},
  };
  for (const auto& [text, says] : cases) {
    const std::string error = ListError(text);
    EXPECT_NE(error.find("revocation list /srv/revoked " + says), std::string::npos) << text << ": " << error;
    EXPECT_NE(error.find("Fix: one entry a line"), std::string::npos) << error;
  }
}

TEST(RevocationListTest, LoadFollowsThePrivateFileRules) {
  std::string tmpl = (fs::temp_directory_path() / "snapthread_revoked_XXXXXX").string();
  ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
  const std::string path = tmpl + "/revoked";
  std::ofstream(path) << "device left\n";
  ASSERT_EQ(chmod(path.c_str(), 0600), 0);
  EXPECT_TRUE(RevocationList::Load(path).IsRevoked(Role::kDevice, "left", KeyId{}));
  ASSERT_EQ(chmod(path.c_str(), 0666), 0);
  try {
    RevocationList::Load(path);
    ADD_FAILURE() << "a world-writable list was read";
  } catch (const RevocationListError& e) {
    EXPECT_NE(std::string(e.what()).find("revocation list " + path + " has mode 0666"), std::string::npos) << e.what();
  }
  EXPECT_THROW(RevocationList::Load(tmpl + "/none"), RevocationListError);
  fs::remove_all(tmpl);
}

class KeyRingTest : public ::testing::Test {
 protected:
  static constexpr int64_t kNow = 1790000000;
  static constexpr int64_t kExpiry = 1798761600;
  static KeyId IdOf(const SessionKey& root, Role role, const std::string& name, int64_t expiry) {
    return SecretKeyId(KeyIdLabel(role), DeriveRoleKey(root, role, name, expiry));
  }
  static std::string Bytes(const SessionKey* key) {
    return key == nullptr ? "" : std::string(reinterpret_cast<const char*>(key->data()), SessionKey::kBytes);
  }
};

TEST_F(KeyRingTest, ResolvesTheClaimedKeyAndRefusesEveryOtherClaim) {
  const SessionKey root = SessionKey::Generate();
  const Credential left = IssueCredential(root, Role::kDevice, "left", kExpiry);
  KeyRing ring(SessionKey::FromBytes(root.data(), SessionKey::kBytes));
  ResolvedKey r = ring.Resolve(Role::kDevice, "left", kExpiry, left.key_id, kNow);
  ASSERT_EQ(r.verdict, KeyVerdict::kAccepted);
  EXPECT_EQ(Bytes(r.key), Bytes(&*left.secret));
  EXPECT_FALSE(r.previous_root);
  // The same again, from the cache.
  EXPECT_EQ(Bytes(ring.Resolve(Role::kDevice, "left", kExpiry, left.key_id, kNow).key), Bytes(&*left.secret));
  // An extended expiry, another name or role, another id: unknown.
  EXPECT_EQ(ring.Resolve(Role::kDevice, "left", kExpiry + 86400, left.key_id, kNow).verdict, KeyVerdict::kUnknownKey);
  EXPECT_EQ(ring.Resolve(Role::kDevice, "left", kNeverExpires, left.key_id, kNow).verdict, KeyVerdict::kUnknownKey);
  EXPECT_EQ(ring.Resolve(Role::kDevice, "right", kExpiry, left.key_id, kNow).verdict, KeyVerdict::kUnknownKey);
  EXPECT_EQ(ring.Resolve(Role::kOperator, "left", kExpiry, left.key_id, kNow).verdict, KeyVerdict::kUnknownKey);
  EXPECT_EQ(ring.Resolve(Role::kObserver, "", 0, left.key_id, kNow).verdict, KeyVerdict::kInvalidClaim);
  EXPECT_EQ(ring.Resolve(Role::kDevice, "le ft", kExpiry, left.key_id, kNow).verdict, KeyVerdict::kInvalidClaim);
  // Expiry: valid up to, not including, its second.
  EXPECT_EQ(ring.Resolve(Role::kDevice, "left", kExpiry, left.key_id, kExpiry - 1).verdict, KeyVerdict::kAccepted);
  EXPECT_EQ(ring.Resolve(Role::kDevice, "left", kExpiry, left.key_id, kExpiry).verdict, KeyVerdict::kExpired);
  // A key of another root.
  const SessionKey other = SessionKey::Generate();
  EXPECT_EQ(ring.Resolve(Role::kDevice, "left", kExpiry, IdOf(other, Role::kDevice, "left", kExpiry), kNow).verdict,
            KeyVerdict::kUnknownKey);
}

TEST_F(KeyRingTest, RevocationActsOnTheRunningRing) {
  const SessionKey root = SessionKey::Generate();
  KeyRing ring(SessionKey::FromBytes(root.data(), SessionKey::kBytes));
  const KeyId left = IdOf(root, Role::kDevice, "left", 0);
  const KeyId right = IdOf(root, Role::kDevice, "right", 0);
  ASSERT_EQ(ring.Resolve(Role::kDevice, "left", 0, left, kNow).verdict, KeyVerdict::kAccepted);
  ring.SetRevocations(RevocationList::Parse("device left\n", "revoked"));
  EXPECT_EQ(ring.Resolve(Role::kDevice, "left", 0, left, kNow).verdict, KeyVerdict::kRevoked);
  EXPECT_EQ(ring.Resolve(Role::kDevice, "right", 0, right, kNow).verdict, KeyVerdict::kAccepted);
  ring.SetRevocations(RevocationList::Parse("key_id " + KeyIdToHex(right) + "\n", "revoked"));
  EXPECT_EQ(ring.Resolve(Role::kDevice, "right", 0, right, kNow).verdict, KeyVerdict::kRevoked);
  EXPECT_EQ(ring.Resolve(Role::kDevice, "left", 0, left, kNow).verdict, KeyVerdict::kAccepted);
}

TEST_F(KeyRingTest, RotationKeepsThePreviousRootForItsGracePeriod) {
  const SessionKey old_root = SessionKey::Generate();
  const SessionKey new_root = SessionKey::Generate();
  KeyRing ring(SessionKey::FromBytes(old_root.data(), SessionKey::kBytes));
  const PublicKey old_public = ring.signer().public_key();
  const KeyId old_id = IdOf(old_root, Role::kOperator, "alice", 0);
  ASSERT_EQ(ring.Resolve(Role::kOperator, "alice", 0, old_id, kNow).verdict, KeyVerdict::kAccepted);
  ring.Rotate(SessionKey::FromBytes(new_root.data(), SessionKey::kBytes), kNow + 3600);
  EXPECT_EQ(ring.signer().public_key(), DeriveServerPublicKey(new_root));
  ASSERT_NE(ring.previous_signer(kNow), nullptr);
  EXPECT_EQ(ring.previous_signer(kNow)->public_key(), old_public);
  EXPECT_EQ(ring.previous_signer(kNow + 3600), nullptr);
  const KeyId new_id = IdOf(new_root, Role::kOperator, "alice", 0);
  ResolvedKey r = ring.Resolve(Role::kOperator, "alice", 0, new_id, kNow);
  EXPECT_EQ(r.verdict, KeyVerdict::kAccepted);
  EXPECT_FALSE(r.previous_root);
  r = ring.Resolve(Role::kOperator, "alice", 0, old_id, kNow + 3599);
  EXPECT_EQ(r.verdict, KeyVerdict::kAccepted);
  EXPECT_TRUE(r.previous_root);
  const Credential old_alice = IssueCredential(old_root, Role::kOperator, "alice", 0);
  EXPECT_EQ(Bytes(r.key), Bytes(&*old_alice.secret));
  // After the grace period (also from the cache), the old key is refused; the new one not.
  EXPECT_EQ(ring.Resolve(Role::kOperator, "alice", 0, old_id, kNow + 3600).verdict, KeyVerdict::kGraceOver);
  EXPECT_EQ(ring.Resolve(Role::kOperator, "alice", 0, new_id, kNow + 3600).verdict, KeyVerdict::kAccepted);
  // A second rotation drops the oldest root.
  ring.Rotate(SessionKey::Generate(), kNow + 7200);
  EXPECT_EQ(ring.Resolve(Role::kOperator, "alice", 0, old_id, kNow).verdict, KeyVerdict::kUnknownKey);
  EXPECT_EQ(ring.Resolve(Role::kOperator, "alice", 0, new_id, kNow).verdict, KeyVerdict::kAccepted);
}

TEST_F(KeyRingTest, VerdictsHaveWords) {
  for (const KeyVerdict v : {KeyVerdict::kAccepted, KeyVerdict::kExpired, KeyVerdict::kRevoked,
                             KeyVerdict::kUnknownKey, KeyVerdict::kGraceOver, KeyVerdict::kInvalidClaim}) {
    EXPECT_NE(KeyVerdictToString(v), "unknown");
  }
}

}  // namespace key_ring_test
}  // namespace snapthread::auth
