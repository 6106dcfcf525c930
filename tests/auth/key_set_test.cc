// KeySet (auth/key_set.h): what each role's tagger produces and what verifies it, and
// LoadKeySet's refusals of a credential of the wrong role or an expired one (naming the
// role needed) and its acceptance of the root key file for every role.
#include <gtest/gtest.h>

#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "auth/credential.h"
#include "auth/credential_file.h"
#include "auth/key_file.h"
#include "auth/key_set.h"
#include "auth/message_mac.h"
#include "sample_messages.h"

namespace snapthread::auth {
namespace {

constexpr const char* kChannel = "S_KEYSET";

bool AllZero(const uint8_t* bytes, size_t n) {
  return std::all_of(bytes, bytes + n, [](uint8_t b) { return b == 0; });
}

// A solver status tagged by `tagger`, encoded.
std::vector<uint8_t> Tagged(const Tagger& tagger, solver_status_t* m) {
  *m = test_support::Sample<solver_status_t>();
  EXPECT_TRUE(Sign(m, kChannel, 42, 1, tagger));
  return test_support::Encode(*m);
}

TEST(KeySetTest, DeviceAndOperatorTaggersMacWithTheirCredentialSecret) {
  const SessionKey root = SessionKey::Generate();
  for (const Role role : {Role::kDevice, Role::kOperator}) {
    const KeySet keys = KeySet::ForRole(root, role, "alice");
    const Credential issued = IssueCredential(root, role, "alice", kNeverExpires);
    ASSERT_TRUE(issued.secret.has_value());
    solver_status_t m;
    const std::vector<uint8_t> bytes = Tagged(keys.tagger(), &m);
    EXPECT_EQ(m.sender_role, static_cast<int8_t>(role));
    EXPECT_EQ(m.sender_name, "alice");
    EXPECT_EQ(KeyIdFromWire(m.key_id), issued.key_id);
    EXPECT_TRUE(AllZero(m.signature, kSignatureBytes));  // devices and operators do not sign
    EXPECT_TRUE(VerifyMac(bytes.data(), bytes.size(), kChannel, *issued.secret));
    EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), kChannel, root));
    // The same name in the other role holds another key.
    const Role other = role == Role::kDevice ? Role::kOperator : Role::kDevice;
    EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), kChannel, *IssueCredential(root, other, "alice", 0).secret));
  }
}

TEST(KeySetTest, ADeviceStatusCarriesTheDevicesOwnSignatureAndCertificate) {
  const SessionKey root = SessionKey::Generate();
  const KeySet device = KeySet::ForRole(root, Role::kDevice, "hand");
  ASSERT_NE(device.device_status_tagger(), nullptr);
  ASSERT_NE(device.device_public_key(), nullptr);
  ASSERT_NE(device.device_certificate(), nullptr);
  EXPECT_TRUE(VerifyDeviceCertificate(device.server_public_key(), "hand", device.expires_unix_s(),
                                      *device.device_public_key(), device.device_certificate()->data()));
  solver_status_t m;
  const std::vector<uint8_t> bytes = Tagged(*device.device_status_tagger(), &m);
  EXPECT_TRUE(VerifySignature(bytes.data(), bytes.size(), kChannel, *device.device_public_key()));
  EXPECT_FALSE(VerifySignature(bytes.data(), bytes.size(), kChannel, device.server_public_key()));
  EXPECT_TRUE(VerifyMac(bytes.data(), bytes.size(), kChannel, *device.mac_key()));
  EXPECT_EQ(KeySet::ForRole(root, Role::kObserver).device_status_tagger(), nullptr);
}

TEST(KeySetTest, AnObserverTagsNothing) {
  const SessionKey root = SessionKey::Generate();
  const KeySet observer = KeySet::ForRole(root, Role::kObserver);
  EXPECT_EQ(observer.mac_key(), nullptr);
  EXPECT_EQ(observer.tagger().mac_key, nullptr);
  EXPECT_EQ(observer.tagger().signer, nullptr);
  EXPECT_EQ(observer.tagger().previous_signer, nullptr);
  solver_status_t m;
  const std::vector<uint8_t> bytes = Tagged(observer.tagger(), &m);
  EXPECT_TRUE(AllZero(m.mac, kMacBytes));
  EXPECT_TRUE(AllZero(m.signature, kSignatureBytes));
  EXPECT_TRUE(AllZero(m.signature2, kSignatureBytes));
  EXPECT_EQ(m.key_id, 0);
  EXPECT_FALSE(VerifySignature(bytes.data(), bytes.size(), kChannel, observer.server_public_key()));
  EXPECT_FALSE(VerifyMac(bytes.data(), bytes.size(), kChannel, observer.read_key()));
}

TEST(KeySetTest, TheServerSignsWhatEveryCredentialVerifies) {
  const SessionKey root = SessionKey::Generate();
  const KeySet server = KeySet::FromRoot(SessionKey::FromBytes(root.data(), SessionKey::kBytes));
  EXPECT_EQ(server.role(), Role::kServer);
  EXPECT_EQ(server.tagger().mac_key, nullptr);
  solver_status_t m;
  const std::vector<uint8_t> bytes = Tagged(server.tagger(), &m);
  EXPECT_EQ(m.sender_role, static_cast<int8_t>(Role::kServer));
  EXPECT_TRUE(AllZero(m.mac, kMacBytes));
  for (const Role role : {Role::kDevice, Role::kObserver, Role::kOperator}) {
    const KeySet holder = KeySet::FromCredential(IssueCredential(root, role, role == Role::kObserver ? "" : "x", 0));
    EXPECT_EQ(holder.server_public_key(), server.server_public_key());
    EXPECT_TRUE(VerifySignature(bytes.data(), bytes.size(), kChannel, holder.server_public_key()));
  }
  const KeySet stranger = KeySet::ForRole(SessionKey::Generate(), Role::kObserver);
  EXPECT_FALSE(VerifySignature(bytes.data(), bytes.size(), kChannel, stranger.server_public_key()));
}

class LoadKeySetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/snapthread-keyset-XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
    root_path_ = dir_ + "/root.key";
    WriteNewKey(KeyLocation{root_path_, "--key"}, false);
    root_.emplace(LoadKey(KeyLocation{root_path_, "--key"}));
  }
  void TearDown() override {
    for (const std::string& f : files_) unlink(f.c_str());
    unlink(root_path_.c_str());
    rmdir(dir_.c_str());
  }
  std::string Write(const std::string& name, Role role, const std::string& who, int64_t expires) {
    const std::string path = dir_ + "/" + name;
    WriteCredentialFile(path, IssueCredential(*root_, role, who, expires), false);
    files_.push_back(path);
    return path;
  }
  // The message of LoadKeySet's refusal, or "" when it loads.
  static std::string Refusal(const std::string& path, Role needed, const char* program) {
    try {
      (void)LoadKeySet(path, needed, program);
      return "";
    } catch (const std::exception& e) {
      return e.what();
    }
  }

  std::string dir_, root_path_;
  std::optional<SessionKey> root_;
  std::vector<std::string> files_;
};

TEST_F(LoadKeySetTest, ADeviceCredentialIsRefusedWhereAnotherRoleIsNeeded) {
  const std::string device = Write("device.cred", Role::kDevice, "hand", kNeverExpires);
  std::string why = Refusal(device, Role::kObserver, "snapthread-viewer");
  EXPECT_NE(why.find("snapthread-viewer"), std::string::npos) << why;
  EXPECT_NE(why.find("observer"), std::string::npos) << why;
  why = Refusal(device, Role::kServer, "snapthread-server");
  EXPECT_NE(why.find("snapthread-server"), std::string::npos) << why;
  EXPECT_NE(why.find("root key"), std::string::npos) << why;
  why = Refusal(device, Role::kOperator, "snapthread-ctl");
  EXPECT_NE(why.find("operator"), std::string::npos) << why;
  // ... and accepted where a device is needed.
  EXPECT_EQ(Refusal(device, Role::kDevice, "snapthread-device"), "");
  const KeySet keys = LoadKeySet(device, Role::kDevice, "snapthread-device");
  EXPECT_EQ(keys.role(), Role::kDevice);
  EXPECT_EQ(keys.name(), "hand");
  EXPECT_EQ(keys.root(), nullptr);
}

TEST_F(LoadKeySetTest, AnExpiredCredentialIsRefused) {
  const std::string expired = Write("old.cred", Role::kOperator, "alice", 1000);
  const std::string why = Refusal(expired, Role::kOperator, "snapthread-ctl");
  EXPECT_NE(why.find("expired"), std::string::npos) << why;
  EXPECT_NE(why.find("operator"), std::string::npos) << why;
  const std::string fresh = Write("new.cred", Role::kOperator, "alice", 4102444800);  // 2100
  EXPECT_EQ(Refusal(fresh, Role::kOperator, "snapthread-ctl"), "");
}

TEST_F(LoadKeySetTest, TheRootKeyFileIsAcceptedForEveryRole) {
  for (const Role role : {Role::kServer, Role::kDevice, Role::kObserver, Role::kOperator}) {
    const KeySet keys = LoadKeySet(root_path_, role, "snapthread-test");
    EXPECT_EQ(keys.role(), Role::kServer) << RoleToString(role);
    ASSERT_NE(keys.root(), nullptr);
    EXPECT_EQ(keys.root()->Id(), root_->Id());
    EXPECT_EQ(keys.server_public_key(), KeySet::ForRole(*root_, Role::kObserver).server_public_key());
  }
}

}  // namespace
}  // namespace snapthread::auth
