// snapthread-keygen run as a program for each of its modes: credentials it issues load
// with the right role, name, expiry and certificate; --rotate keeps the old key in
// FILE.previous; --revoke lines load as a revocation list; bad arguments exit 2 with a
// message, and nothing is written for them.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

#include "auth/credential_file.h"
#include "auth/device_certificate.h"
#include "auth/key_file.h"
#include "auth/revocation_list.h"
#include "auth/role_keys.h"
#include "child_process.h"
#include "environment.h"
#include "temp_dir.h"

namespace snapthread::auth {
namespace keygen_process_test {

using test_support::ChildProcess;
using test_support::ProcessResult;

class KeygenProcessTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_EQ(Run({}).exit_code, 0) << "making the root key"; }

  std::string Path(const std::string& name) const { return dir_.path() + "/" + name; }
  // snapthread-keygen --key ROOT args..., its exit status and output.
  ProcessResult Run(const std::vector<std::string>& args) {
    std::vector<std::string> argv = {test_support::BinDir() + "/snapthread-keygen", "--key", root_};
    argv.insert(argv.end(), args.begin(), args.end());
    ChildProcess child(argv, test_support::OutputFiles(Path("out.txt"), Path("err.txt")));
    EXPECT_TRUE(child.started());
    return child.Finish(30.0);
  }
  static std::string Bytes(const SessionKey& key) {
    return std::string(reinterpret_cast<const char*>(key.data()), SessionKey::kBytes);
  }
  static unsigned ModeOf(const std::string& path) {
    struct stat st {};
    return stat(path.c_str(), &st) == 0 ? st.st_mode & 07777 : 0;
  }
  SessionKey Root() const { return LoadKey({root_, "--key"}); }

  test_support::ScopedTempDir dir_{"keygen"};
  std::string root_ = dir_.path() + "/root.key";
};

TEST_F(KeygenProcessTest, IssuesEachRolesCredential) {
  const int64_t now = static_cast<int64_t>(std::time(nullptr));
  const std::string device = Path("left.cred");
  ProcessResult r = Run({"--role", "device", "--device", "left", "--expires-in", "30d", "--out", device,
                         "--host", "labpc"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const Credential c = LoadCredential(device);
  EXPECT_EQ(c.role, Role::kDevice);
  EXPECT_EQ(c.name, "left");
  EXPECT_GE(c.expires_unix_s, now + 30 * 86400);
  EXPECT_LE(c.expires_unix_s, now + 30 * 86400 + 60);
  EXPECT_EQ(c.root_id, RootKeyId(Root()));
  EXPECT_EQ(Bytes(*c.secret), Bytes(DeriveDeviceKey(Root(), "left", c.expires_unix_s)));
  ASSERT_TRUE(c.certificate.has_value());
  EXPECT_TRUE(VerifyDeviceCertificate(DeriveServerPublicKey(Root()), "left", c.expires_unix_s,
                                      DeriveDeviceSigner(*c.secret).public_key(), c.certificate->data()));
  EXPECT_EQ(ModeOf(device), 0600u);
  for (const std::string& said : {device, std::string("role     device"), std::string("name     left"),
                                  KeyIdToHex(c.key_id), std::to_string(c.expires_unix_s),
                                  "scp -p " + device + " labpc:.config/snapthread/left.cred"}) {
    EXPECT_NE(r.out.find(said), std::string::npos) << said << " in\n" << r.out;
  }
  // Not overwritten without --force (exit 1, the file kept); replaced with it.
  r = Run({"--role", "device", "--device", "left", "--out", device});
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("refusing to overwrite"), std::string::npos) << r.err;
  EXPECT_EQ(LoadCredential(device).expires_unix_s, c.expires_unix_s);
  r = Run({"--role", "device", "--device", "left", "--out", device, "--force"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(LoadCredential(device).expires_unix_s, kNeverExpires);

  // Defaults: a device is "hand", an operator "operator"; an absolute expiry.
  ASSERT_EQ(Run({"--role", "device", "--out", Path("hand.cred")}).exit_code, 0);
  EXPECT_EQ(LoadCredential(Path("hand.cred")).name, "hand");
  ASSERT_EQ(Run({"--role", "operator", "--out", Path("op.cred"), "--expires", "4102444800"}).exit_code, 0);
  const Credential op = LoadCredential(Path("op.cred"));
  EXPECT_EQ(op.role, Role::kOperator);
  EXPECT_EQ(op.name, "operator");
  EXPECT_EQ(op.expires_unix_s, 4102444800);
  EXPECT_FALSE(op.certificate.has_value());
  ASSERT_EQ(Run({"--role", "operator", "--name", "alice", "--out", Path("alice.cred")}).exit_code, 0);
  EXPECT_EQ(LoadCredential(Path("alice.cred")).name, "alice");
  r = Run({"--role", "observer", "--out", Path("obs.cred"), "--expires-in", "12h"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Credential obs = LoadCredential(Path("obs.cred"));
  EXPECT_EQ(obs.role, Role::kObserver);
  EXPECT_TRUE(obs.name.empty());
  EXPECT_FALSE(obs.secret.has_value());
  EXPECT_NEAR(static_cast<double>(obs.expires_unix_s), static_cast<double>(now + 12 * 3600), 60.0);

  // --show prints the ids and no secret.
  r = Run({"--show", device});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Credential shown = LoadCredential(device);
  EXPECT_NE(r.out.find(KeyIdToHex(shown.key_id)), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("name     left"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(ToHex(shown.secret->data(), 8)), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(ToHex(shown.read_key->data(), 8)), std::string::npos) << r.out;
}

TEST_F(KeygenProcessTest, RotationKeepsTheOldKeyAsPrevious) {
  const std::string old_bytes = Bytes(Root());
  const std::string old_id = Root().Id();
  ProcessResult r = Run({"--rotate"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const SessionKey previous = LoadKey({root_ + ".previous", "test"});
  EXPECT_EQ(Bytes(previous), old_bytes);
  EXPECT_NE(Bytes(Root()), old_bytes);
  EXPECT_EQ(ModeOf(root_ + ".previous"), 0600u);
  EXPECT_EQ(ModeOf(root_), 0600u);
  for (const std::string& said : {old_id, Root().Id(), root_ + ".previous", std::string("--role device"),
                                  std::string("kill -HUP"), std::string("--key-grace-s")}) {
    EXPECT_NE(r.out.find(said), std::string::npos) << said << " in\n" << r.out;
  }
  // A second rotation replaces the older FILE.previous with the key it replaces.
  const std::string second = Bytes(Root());
  ASSERT_EQ(Run({"--rotate"}).exit_code, 0);
  EXPECT_EQ(Bytes(LoadKey({root_ + ".previous", "test"})), second);
  EXPECT_NE(Bytes(Root()), second);
  EXPECT_NE(Bytes(Root()), old_bytes);
  // Credentials issued now come from the new root.
  ASSERT_EQ(Run({"--role", "device", "--out", Path("hand.cred")}).exit_code, 0);
  EXPECT_EQ(LoadCredential(Path("hand.cred")).root_id, RootKeyId(Root()));
  // No root key, nothing to rotate: exit 1.
  std::filesystem::remove(root_);
  r = Run({"--rotate"});
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.err.find("no session key at " + root_), std::string::npos) << r.err;
}

TEST_F(KeygenProcessTest, RevocationLinesLoadAndNameTheDevice) {
  const std::string list_path = root_ + ".revoked";
  ProcessResult r = Run({"--revoke", "left"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(ModeOf(list_path), 0600u);
  EXPECT_NE(r.out.find("kill -HUP"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("device left"), std::string::npos) << r.out;
  RevocationList list = RevocationList::Load(list_path);
  EXPECT_TRUE(list.IsRevoked(Role::kDevice, "left", KeyId{}));
  EXPECT_FALSE(list.IsRevoked(Role::kDevice, "right", KeyId{}));
  EXPECT_FALSE(list.IsRevoked(Role::kOperator, "left", KeyId{}));
  ASSERT_EQ(Run({"--revoke", "alice", "--role", "operator"}).exit_code, 0);
  const KeyId id = *KeyIdFromHex("0123456789abcdef");
  ASSERT_EQ(Run({"--revoke-key-id", "0123456789ABCDEF"}).exit_code, 0);
  ASSERT_EQ(Run({"--revoke", "left"}).exit_code, 0);  // again: nothing added
  list = RevocationList::Load(list_path);
  EXPECT_EQ(list.size(), 3u);
  EXPECT_TRUE(list.IsRevoked(Role::kOperator, "alice", KeyId{}));
  EXPECT_TRUE(list.IsRevoked(Role::kObserver, "", id));
  r = Run({"--list-revoked"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* said : {"device left", "operator alice", "key_id 0123456789abcdef", "3 entries"}) {
    EXPECT_NE(r.out.find(said), std::string::npos) << said << " in\n" << r.out;
  }
  // Issuing a revoked name warns.
  r = Run({"--role", "device", "--device", "left", "--out", Path("left.cred")});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("revokes this credential"), std::string::npos) << r.err;
  // A list that would not load is refused and left as it is.
  const std::string broken = test_support::ReadFile(list_path) + "grasp left\n";
  {
    std::FILE* f = std::fopen(list_path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs(broken.c_str(), f);
    std::fclose(f);
  }
  r = Run({"--revoke", "right"});
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.err.find("revocation list " + list_path + " line"), std::string::npos) << r.err;
  EXPECT_EQ(test_support::ReadFile(list_path), broken);
}

TEST_F(KeygenProcessTest, BadArgumentsExit2WithAMessage) {
  struct Case {
    std::vector<std::string> args;
    std::string says;
  };
  const std::vector<Case> cases = {
      {{"--role", "server", "--out", Path("s.cred")}, "holds the root key itself"},
      {{"--role", "admin", "--out", Path("a.cred")}, "expected device, operator or observer"},
      {{"--role", "device"}, "--role needs --out FILE"},
      {{"--role", "device", "--device", "a b", "--out", Path("d.cred")}, "not a valid device name"},
      {{"--role", "device", "--device", "l", "--name", "r", "--out", Path("d.cred")}, "not both"},
      {{"--role", "operator", "--device", "l", "--out", Path("d.cred")}, "an operator's name is --name"},
      {{"--role", "observer", "--name", "v", "--out", Path("d.cred")}, "observer credential has no name"},
      {{"--role", "device", "--expires-in", "5x", "--out", Path("d.cred")}, "unit s, m, h, d or w"},
      {{"--role", "device", "--expires-in", "0d", "--out", Path("d.cred")}, "positive count"},
      {{"--role", "device", "--expires", "100", "--out", Path("d.cred")}, "not in the future"},
      {{"--role", "device", "--expires", "1d", "--out", Path("d.cred")}, "Unix seconds"},
      {{"--role", "device", "--expires", "4102444800", "--expires-in", "1d", "--out", Path("d.cred")}, "not both"},
      {{"--rotate", "--role", "device"}, "choose one of"},
      {{"--rotate", "--out", Path("d.cred")}, "--out does not go with --rotate"},
      {{"--revoke", "left", "--role", "observer"}, "rotate the root key"},
      {{"--revoke", "le/ft"}, "a name is 1 to 32"},
      {{"--revoke-key-id", "zz"}, "16 hex digits"},
      {{"--revoke-key-id", "0123456789abcdef", "--role", "device"}, "--role goes with --revoke NAME"},
      {{"--list-revoked", "--force"}, "--force does not go with --list-revoked"},
      {{"--no-such-flag"}, "--no-such-flag"},
  };
  const std::string root_bytes = Bytes(Root());
  for (const Case& c : cases) {
    const ProcessResult r = Run(c.args);
    std::string line;
    for (const std::string& a : c.args) line += a + " ";
    EXPECT_EQ(r.exit_code, 2) << line << "\n" << r.out << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << line << "\n" << r.err;
  }
  // Nothing was written.
  EXPECT_FALSE(std::filesystem::exists(Path("s.cred")));
  EXPECT_FALSE(std::filesystem::exists(Path("d.cred")));
  EXPECT_FALSE(std::filesystem::exists(root_ + ".revoked"));
  EXPECT_FALSE(std::filesystem::exists(root_ + ".previous"));
  EXPECT_EQ(Bytes(Root()), root_bytes);
}

}  // namespace keygen_process_test
}  // namespace snapthread::auth
