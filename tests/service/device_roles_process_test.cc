// snapthread-device as a process on role credentials: a credential of another role, or of
// another device than the grasp it holds, refuses to start with a message naming what is
// needed; SIGHUP reloads the --key file without stopping it (a bad file keeps the
// credential it has and says which file failed).
#include <gtest/gtest.h>

#include <signal.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "auth/credential.h"
#include "auth/credential_file.h"
#include "auth/role.h"
#include "auth/session_key.h"
#include "test_support.h"

namespace snapthread::device {
namespace {

using test_support::ChildProcess;

std::string DeviceBinary() { return test_support::BinDir() + "/snapthread-device"; }

std::string WriteCredential(const std::string& path, const auth::SessionKey& root, auth::Role role,
                            const std::string& name) {
  auth::WriteCredentialFile(path, auth::IssueCredential(root, role, name, auth::kNeverExpires), true);
  return path;
}

// A device run that needs no server: the sim-path backend along an explicit path.
std::vector<std::string> DeviceArgs(const std::string& dir, const std::string& key, const std::string& duration) {
  {
    std::ofstream path(dir + "/path.csv");
    path << "0,0\n0.01,0.005\n";
  }
  return {DeviceBinary(), "--backend", "sim-path", "--path-csv", dir + "/path.csv", "--key", key,
          "--session", test_support::UniqueSession("DEVROLES"), "--lcm-url", test_support::kLoopbackLcmUrl,
          "--duration", duration, "--no-rt"};
}

TEST(DeviceRolesProcessTest, ObserverAndOperatorCredentialsRefuseToStartNamingTheDeviceRole) {
  const test_support::ScopedTempDir scoped("device_roles");
  const auth::SessionKey root = auth::SessionKey::Generate();
  for (const auth::Role role : {auth::Role::kObserver, auth::Role::kOperator}) {
    const std::string word(auth::RoleToString(role));
    SCOPED_TRACE(word);
    const std::string key = WriteCredential(scoped.path() + "/" + word + ".cred", root, role,
                                            role == auth::Role::kOperator ? "alice" : "");
    ChildProcess device(DeviceArgs(scoped.path(), key, "5"), test_support::OneLog(scoped.path() + "/" + word + ".log"));
    ASSERT_TRUE(device.started());
    const test_support::ProcessResult r = device.Finish(10.0);
    ASSERT_TRUE(r.exited) << r.out;
    EXPECT_NE(r.exit_code, 0) << r.out;
    EXPECT_LT(r.exit_code, 128) << "a clean exit, not a signal\n" << r.out;
    EXPECT_NE(r.out.find("snapthread-device"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("device"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(word), std::string::npos) << r.out;  // says what the file is
    EXPECT_EQ(r.out.find("terminate called"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("servo"), std::string::npos) << "started anyway\n" << r.out;
  }
}

TEST(DeviceRolesProcessTest, AnotherDevicesCredentialRefusesToStartForThisGrasp) {
  const test_support::ScopedTempDir scoped("device_roles");
  const auth::SessionKey root = auth::SessionKey::Generate();
  const std::string key = WriteCredential(scoped.path() + "/left.cred", root, auth::Role::kDevice, "left");
  ChildProcess device({DeviceBinary(), "--backend", "sim-path", "--scene", test_support::ScenePath("knot_overhand.yaml"),
                       "--grasp", "right", "--key", key, "--session", test_support::UniqueSession("DEVROLES"),
                       "--lcm-url", test_support::kLoopbackLcmUrl, "--duration", "5", "--no-rt"},
                      test_support::OneLog(scoped.path() + "/device.log"));
  ASSERT_TRUE(device.started());
  const test_support::ProcessResult r = device.Finish(10.0);
  ASSERT_TRUE(r.exited) << r.out;
  EXPECT_NE(r.exit_code, 0) << r.out;
  EXPECT_LT(r.exit_code, 128) << r.out;
  EXPECT_NE(r.out.find("'left'"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("'right'"), std::string::npos) << r.out;
}

TEST(DeviceRolesProcessTest, SighupReloadsTheCredentialAndABadFileKeepsTheOldOne) {
  const test_support::ScopedTempDir scoped("device_roles");
  const auth::SessionKey root = auth::SessionKey::Generate();
  const std::string key = WriteCredential(scoped.path() + "/hand.cred", root, auth::Role::kDevice, "hand");
  ChildProcess device(DeviceArgs(scoped.path(), key, "0"), test_support::OneLog(scoped.path() + "/device.log"));
  ASSERT_TRUE(device.started());
  ASSERT_TRUE(device.WaitForOutput("as device 'hand'", 15.0)) << device.Out();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the client runs
  {
    std::ofstream bad(key, std::ios::trunc);
    bad << "not a credential\n";
  }
  device.Signal(SIGHUP);
  EXPECT_TRUE(device.WaitForOutput("reload of " + key + " failed", 5.0)) << device.Out();
  EXPECT_TRUE(device.running()) << device.Out();
  // The server host rotated: a new credential for the same device.
  WriteCredential(key, auth::SessionKey::Generate(), auth::Role::kDevice, "hand");
  device.Signal(SIGHUP);
  EXPECT_TRUE(device.WaitForOutput("reloaded " + key, 5.0)) << device.Out();
  EXPECT_TRUE(device.running()) << device.Out();
  // Another device's credential is refused on reload too.
  WriteCredential(key, root, auth::Role::kDevice, "left");
  device.Signal(SIGHUP);
  EXPECT_TRUE(device.WaitForOutput("reload of " + key + " refused", 5.0)) << device.Out();
  device.Signal(SIGTERM);
  const test_support::ProcessResult r = device.Finish(10.0);
  EXPECT_TRUE(r.exited);
  EXPECT_EQ(r.exit_code, 0) << r.out;
}

}  // namespace
}  // namespace snapthread::device
