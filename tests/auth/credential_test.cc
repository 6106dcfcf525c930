// Credentials (auth/credential.h, auth/credential_file.h): issue, write, load; tampering
// with a device's name or expiry gives a key the server does not re-derive; every
// malformed file is refused naming the file, the line and the fix; the private file rules.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include "auth/credential.h"
#include "auth/credential_file.h"
#include "auth/device_certificate.h"
#include "auth/role_keys.h"

namespace snapthread::auth {
namespace credential_test {

namespace fs = std::filesystem;

std::string KeyBytes(const SessionKey& key) {
  return std::string(reinterpret_cast<const char*>(key.data()), SessionKey::kBytes);
}

class CredentialFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "snapthread_cred_XXXXXX").string();
    ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (fs::path(dir_) / name).string(); }

  std::string WriteText(const std::string& name, const std::string& text, mode_t mode = 0600) {
    const std::string path = Path(name);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
    EXPECT_EQ(chmod(path.c_str(), mode), 0);
    return path;
  }
  static std::string ReadText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  // The CredentialError LoadCredential throws ("" when it loads).
  static std::string LoadError(const std::string& path) {
    try {
      LoadCredential(path);
    } catch (const CredentialError& e) {
      return e.what();
    }
    return "";
  }

  SessionKey root_ = SessionKey::Generate();
  std::string dir_;
};

TEST_F(CredentialFileTest, DeviceCredentialRoundTrip) {
  const Credential issued = IssueCredential(root_, Role::kDevice, "left", 1798761600);
  const std::string path = Path("left.cred");
  WriteCredentialFile(path, issued, false);
  struct stat st {};
  ASSERT_EQ(stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0600u);
  const Credential loaded = LoadCredential(path);
  EXPECT_EQ(loaded.role, Role::kDevice);
  EXPECT_EQ(loaded.name, "left");
  EXPECT_EQ(loaded.expires_unix_s, 1798761600);
  EXPECT_EQ(loaded.root_id, RootKeyId(root_));
  EXPECT_EQ(loaded.key_id, SecretKeyId("device", DeriveDeviceKey(root_, "left", 1798761600)));
  EXPECT_EQ(loaded.server_public_key, DeriveServerPublicKey(root_));
  EXPECT_EQ(KeyBytes(*loaded.secret), KeyBytes(DeriveDeviceKey(root_, "left", 1798761600)));
  EXPECT_EQ(KeyBytes(*loaded.read_key), KeyBytes(DeriveReadKey(root_)));
  ASSERT_TRUE(loaded.certificate.has_value());
  EXPECT_EQ(*loaded.certificate, *issued.certificate);
  EXPECT_TRUE(VerifyDeviceCertificate(DeriveServerPublicKey(root_), "left", 1798761600,
                                      DeriveDeviceSigner(DeriveDeviceKey(root_, "left", 1798761600)).public_key(),
                                      loaded.certificate->data()));
  EXPECT_TRUE(loaded.ExpiredAt(1798761600));
  EXPECT_FALSE(loaded.ExpiredAt(1798761599));
  EXPECT_EQ(ReadText(path).rfind("snapthread-credential 1\nrole device\nname left\nexpires 1798761600\n", 0), 0u);
  // Not overwritten unless asked.
  try {
    WriteCredentialFile(path, issued, false);
    ADD_FAILURE() << "overwrote";
  } catch (const CredentialError& e) {
    EXPECT_NE(std::string(e.what()).find("refusing to overwrite"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(WriteCredentialFile(path, IssueCredential(root_, Role::kDevice, "left", 0), true));
  EXPECT_EQ(LoadCredential(path).expires_unix_s, kNeverExpires);
}

TEST_F(CredentialFileTest, ObserverAndOperatorRoundTrip) {
  const std::string obs = Path("observer.cred");
  WriteCredentialFile(obs, IssueCredential(root_, Role::kObserver, "", 0), false);
  const Credential o = LoadCredential(obs);
  EXPECT_EQ(o.role, Role::kObserver);
  EXPECT_TRUE(o.name.empty());
  EXPECT_FALSE(o.secret.has_value());
  EXPECT_EQ(ReadText(obs).find("secret"), std::string::npos);
  EXPECT_EQ(ReadText(obs).find("name"), std::string::npos);
  EXPECT_FALSE(o.certificate.has_value());
  EXPECT_EQ(ReadText(obs).find("certificate"), std::string::npos);
  const std::string op = Path("alice.cred");
  WriteCredentialFile(op, IssueCredential(root_, Role::kOperator, "alice", 0), false);
  EXPECT_EQ(KeyBytes(*LoadCredential(op).secret), KeyBytes(DeriveOperatorKey(root_, "alice", 0)));
  EXPECT_FALSE(LoadCredential(op).certificate.has_value());
  EXPECT_EQ(ReadText(op).find("certificate"), std::string::npos);
}

TEST_F(CredentialFileTest, TamperedExpiryOrNameGivesAKeyTheServerDoesNotDerive) {
  // A later expiry, never, or another name written into the file: the key the holder has
  // is never the one the server re-derives for that claim. An operator's file still parses
  // (it carries no certificate); a device's is refused at load, its certificate binding
  // the name and the expiry.
  struct Edit {
    std::string from, to, name;
    int64_t expires;
  };
  for (const Role role : {Role::kOperator, Role::kDevice}) {
    const std::string own = role == Role::kDevice ? "left" : "alice";
    const std::string path = Path(own + ".cred");
    WriteCredentialFile(path, IssueCredential(root_, role, own, 1798761600), false);
    const std::string text = ReadText(path);
    const std::string held = KeyBytes(DeriveRoleKey(root_, role, own, 1798761600));
    for (const Edit& e : {Edit{"expires 1798761600", "expires 1898761600", own, 1898761600},
                          Edit{"expires 1798761600", "expires never", own, kNeverExpires},
                          Edit{"name " + own, "name right", "right", 1798761600}}) {
      std::string edited = text;
      edited.replace(edited.find(e.from), e.from.size(), e.to);
      const std::string file = WriteText("edited.cred", edited);
      const std::string claimed = KeyBytes(DeriveRoleKey(root_, role, e.name, e.expires));
      EXPECT_NE(held, claimed) << e.to;
      if (role == Role::kDevice) {
        const std::string error = LoadError(file);
        EXPECT_NE(error.find("credential " + file + " line 10: 'certificate' does not verify"), std::string::npos)
            << e.to << ": " << error;
        continue;
      }
      const Credential c = LoadCredential(file);
      EXPECT_EQ(c.name, e.name);
      EXPECT_EQ(c.expires_unix_s, e.expires);
      EXPECT_EQ(KeyBytes(*c.secret), held) << e.to;
      EXPECT_NE(c.key_id, SecretKeyId("operator", DeriveOperatorKey(root_, c.name, c.expires_unix_s))) << e.to;
    }
  }
}

// Each malformed text, the line it names, and a piece of the message.
struct Malformed {
  std::string label;
  std::function<std::string(std::string)> edit;
  std::string line;  // "line N" or "" (missing lines name no line)
  std::string says;
};

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  if (at == std::string::npos) return "<" + from + " not found>";
  return text.replace(at, from.size(), to);
}
std::string DropLine(std::string text, const std::string& word) {
  const std::size_t at = text.find("\n" + word + " ");
  if (at == std::string::npos) return "<" + word + " not found>";
  return text.erase(at + 1, text.find('\n', at + 1) - at);
}

TEST_F(CredentialFileTest, EveryMalformedFileIsRefusedWithFileLineAndFix) {
  const std::string good_path = Path("good.cred");
  WriteCredentialFile(good_path, IssueCredential(root_, Role::kDevice, "left", 1798761600), false);
  const std::string good = ReadText(good_path);
  // Lines: 1 header, 2 role, 3 name, 4 expires, 5 root_id, 6 key_id, 7 server_public_key,
  // 8 read_key, 9 secret, 10 certificate.
  const std::string secret_hex = good.substr(good.find("secret ") + 7, 64);
  const std::string cert_hex = good.substr(good.find("certificate ") + 12, 128);
  const std::string other_root_cert = [] {
    const std::string t = FormatCredential(IssueCredential(SessionKey::Generate(), Role::kDevice, "left", 1798761600));
    return t.substr(t.find("certificate ") + 12, 128);
  }();
  // One hex digit of the certificate changed.
  const std::string flipped_cert = cert_hex.substr(0, 40) + (cert_hex[40] == '0' ? '1' : '0') + cert_hex.substr(41);
  const std::vector<Malformed> cases = {
      {"empty", [](std::string) { return std::string(); }, "", "empty"},
      {"not a credential", [](std::string) { return std::string("\x01\x02garbage"); }, "line 1", "does not start with"},
      {"other version", [](std::string t) { return Replace(t, "credential 1", "credential 2"); }, "line 1", "format version '2'"},
      {"unknown line", [](std::string t) { return t + "colour blue\n"; }, "line 11", "unknown line 'colour'"},
      {"duplicate", [](std::string t) { return t + "name left\n"; }, "line 11", "a second 'name' line (the first is line 3)"},
      {"missing secret", [](std::string t) { return DropLine(t, "secret"); }, "", "no 'secret' line"},
      {"missing expires", [](std::string t) { return DropLine(t, "expires"); }, "", "no 'expires' line"},
      {"missing name", [](std::string t) { return DropLine(t, "name"); }, "", "no 'name' line"},
      {"missing role", [](std::string t) { return DropLine(t, "role"); }, "", "no 'role' line"},
      {"bad role", [](std::string t) { return Replace(t, "role device", "role admin"); }, "line 2", "device, operator or observer"},
      {"server role", [](std::string t) { return Replace(t, "role device", "role server"); }, "line 2", "root key file"},
      {"bad name", [](std::string t) { return Replace(t, "name left", "name le/ft"); }, "line 3", "1 to 32 of"},
      {"long name", [](std::string t) { return Replace(t, "name left", "name " + std::string(33, 'a')); }, "line 3", "1 to 32 of"},
      {"two values", [](std::string t) { return Replace(t, "name left", "name left right"); }, "line 3", "exactly one value"},
      {"no value", [](std::string t) { return Replace(t, "name left", "name"); }, "line 3", "no value"},
      {"bad expiry", [](std::string t) { return Replace(t, "expires 1798761600", "expires soon"); }, "line 4", "'expires' is 'never'"},
      {"negative expiry", [](std::string t) { return Replace(t, "expires 1798761600", "expires -5"); }, "line 4", "'expires' is 'never'"},
      {"zero expiry", [](std::string t) { return Replace(t, "expires 1798761600", "expires 0"); }, "line 4", "'expires' is 'never'"},
      {"huge expiry", [](std::string t) { return Replace(t, "expires 1798761600", "expires 99999999999999999999"); }, "line 4", "'expires' is 'never'"},
      {"short key id", [](std::string t) { return Replace(t, "key_id ", "key_id 0"); }, "line 6", "16 hex digits (17 characters"},
      {"bad hex", [&](std::string t) { return Replace(t, secret_hex, "zz" + secret_hex.substr(2)); }, "line 9", "not all hex"},
      {"short secret", [&](std::string t) { return Replace(t, secret_hex, secret_hex.substr(2)); }, "line 9", "64 hex digits (62 characters"},
      {"edited secret", [&](std::string t) { return Replace(t, secret_hex, std::string(64, '0')); }, "line 6", "does not match the key"},
      {"crlf", [](std::string t) { return Replace(t, "name left\n", "name left\r\n"); }, "line 3", "carriage return"},
      {"empty line", [](std::string t) { return Replace(t, "name left\n", "name left\n\n"); }, "line 4", "an empty line"},
      {"missing certificate", [](std::string t) { return DropLine(t, "certificate"); }, "", "no 'certificate' line (a device credential needs one)"},
      {"short certificate", [&](std::string t) { return Replace(t, cert_hex, cert_hex.substr(2)); }, "line 10", "128 hex digits (126 characters"},
      {"edited certificate", [&](std::string t) { return Replace(t, cert_hex, flipped_cert); }, "line 10", "'certificate' does not verify"},
      {"certificate of another root", [&](std::string t) { return Replace(t, cert_hex, other_root_cert); }, "line 10", "'certificate' does not verify"},
      {"operator with certificate", [](std::string t) { return Replace(t, "role device", "role operator"); }, "line 10", "an operator credential has no 'certificate' line"},
      {"observer with secret", [](std::string t) { return Replace(DropLine(t, "name"), "role device", "role observer"); }, "line 8", "an observer credential has no 'secret' line"},
  };
  for (const Malformed& m : cases) {
    const std::string text = m.edit(good);
    ASSERT_EQ(text.find("not found>"), std::string::npos) << m.label;
    const std::string path = WriteText("bad.cred", text);
    const std::string error = LoadError(path);
    EXPECT_NE(error.find("credential " + path + (m.line.empty() ? ":" : " " + m.line + ":")), std::string::npos)
        << m.label << ": " << error;
    EXPECT_NE(error.find(m.says), std::string::npos) << m.label << ": " << error;
    EXPECT_NE(error.find("Fix: "), std::string::npos) << m.label << ": " << error;
    // A refusal never shows a secret.
    EXPECT_EQ(error.find(secret_hex.substr(0, 16)), std::string::npos) << m.label << ": " << error;
  }
}

TEST_F(CredentialFileTest, FileRulesOfTheKeyFileApply) {
  const std::string path = Path("left.cred");
  WriteCredentialFile(path, IssueCredential(root_, Role::kDevice, "left", 0), false);
  ASSERT_EQ(chmod(path.c_str(), 0640), 0);
  std::string error = LoadError(path);
  EXPECT_NE(error.find("credential " + path + " has mode 0640"), std::string::npos) << error;
  EXPECT_NE(error.find("chmod 0600 " + path), std::string::npos) << error;
  ASSERT_EQ(chmod(path.c_str(), 0600), 0);
  const std::string link = Path("link.cred");
  ASSERT_EQ(symlink(path.c_str(), link.c_str()), 0);
  error = LoadError(link);
  EXPECT_NE(error.find("symbolic link"), std::string::npos) << error;
  EXPECT_NE(error.find("--credential " + fs::canonical(path).string()), std::string::npos) << error;
  error = LoadError(Path("missing.cred"));
  EXPECT_NE(error.find("no credential at " + Path("missing.cred")), std::string::npos) << error;
  EXPECT_NE(error.find("snapthread-keygen --role"), std::string::npos) << error;
  error = LoadError(dir_);
  EXPECT_NE(error.find("is a directory"), std::string::npos) << error;
  const std::string big = WriteText("big.cred", std::string(kMaxCredentialFileBytes + 1, 'x'));
  EXPECT_NE(LoadError(big).find("at most 4096"), std::string::npos) << LoadError(big);
  ASSERT_EQ(chmod(dir_.c_str(), 0777), 0);
  EXPECT_NE(LoadError(path).find("chmod go-w " + dir_), std::string::npos) << LoadError(path);
  ASSERT_EQ(chmod(dir_.c_str(), 0700), 0);
}

TEST(CredentialTest, IssueRefusesAServerCredentialAndBadNames) {
  const SessionKey root = SessionKey::Generate();
  EXPECT_THROW(IssueCredential(root, Role::kServer, "", 0), CredentialError);
  EXPECT_THROW(IssueCredential(root, Role::kDevice, "", 0), CredentialError);
  EXPECT_THROW(IssueCredential(root, Role::kDevice, "a b", 0), CredentialError);
  EXPECT_THROW(IssueCredential(root, Role::kObserver, "viewer1", 0), CredentialError);
  EXPECT_THROW(IssueCredential(root, Role::kOperator, "alice", -1), CredentialError);
}

TEST(CredentialTest, TheWrongRoleIsRefusedNamingTheRoleNeeded) {
  const SessionKey root = SessionKey::Generate();
  const Credential observer = IssueCredential(root, Role::kObserver, "", 0);
  EXPECT_NO_THROW(RequireRole(observer, Role::kObserver, "snapthread-viewer", "/c/obs.cred"));
  try {
    RequireRole(observer, Role::kDevice, "snapthread-device", "/c/obs.cred");
    ADD_FAILURE() << "an observer credential passed as a device's";
  } catch (const CredentialError& e) {
    EXPECT_STREQ(e.what(),
                 "snapthread-device needs a device credential; /c/obs.cred is an observer credential. "
                 "Fix: pass the device credential issued for this host (snapthread-keygen --role device "
                 "on the server host)");
  }
  const Credential left = IssueCredential(root, Role::kDevice, "left", 0);
  try {
    RequireRole(left, Role::kOperator, "snapthread-ctl", "left.cred");
    ADD_FAILURE() << "a device credential passed as an operator's";
  } catch (const CredentialError& e) {
    EXPECT_NE(std::string(e.what()).find("needs an operator credential; left.cred is a device credential (left)"),
              std::string::npos)
        << e.what();
  }
}

TEST(CredentialTest, RoleWordsRoundTrip) {
  for (const Role role : {Role::kServer, Role::kDevice, Role::kObserver, Role::kOperator}) {
    EXPECT_EQ(RoleFromString(RoleToString(role)), role);
  }
  EXPECT_FALSE(RoleFromString("Device"));
  EXPECT_FALSE(RoleFromString(""));
}

}  // namespace credential_test
}  // namespace snapthread::auth
