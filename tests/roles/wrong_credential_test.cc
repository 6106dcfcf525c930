// A program given a credential of a role it does not play refuses to start, with a message
// naming the role it needs (issue 25 item 1): the server on an observer's or a device's
// credential (it needs the root key), the device on an observer's or an operator's,
// snapthread-ctl on a device's or an observer's, the viewer and the web bridge on a
// device's. Each exits non-zero within its start-up, before it sends anything.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "role_session.h"
#include "test_support.h"

namespace snapthread::roles_test {
namespace {

using test_support::ProcessResult;

class WrongCredentialTest : public RoleSessionTest {
 protected:
  // Runs `program` with `key` and `args` and expects a non-zero exit whose output holds `role`.
  void ExpectRefused(const std::string& program, const std::string& key, const std::vector<std::string>& args,
                     const std::string& role) {
    std::vector<std::string> all{"--key", key, "--session", session_, "--lcm-url", test_support::kLoopbackLcmUrl};
    all.insert(all.end(), args.begin(), args.end());
    const ProcessResult r = Run(program, all);
    EXPECT_TRUE(r.exited) << program << " did not exit by itself";
    EXPECT_NE(r.exit_code, 0) << program << " started on " << key << "\n" << r.out << r.err;
    EXPECT_TRUE(ContainsWord(r.out + r.err, role)) << program << " does not name '" << role << "'\n"
                                                    << r.out << r.err;
  }
};

TEST_F(WrongCredentialTest, EachProgramRefusesAnotherRolesCredential) {
  const std::string device = creds_->Issue(auth::Role::kDevice, "hand");
  const std::string observer = creds_->Issue(auth::Role::kObserver);
  const std::string op = creds_->Issue(auth::Role::kOperator, "console");
  const std::vector<std::string> server_args{"--scene", test_support::ScenePath("curve2d_snap.yaml"), "--duration",
                                             "20"};
  const std::vector<std::string> device_args{"--backend", "sim-path", "--scene",
                                             test_support::ScenePath("curve2d_snap.yaml"), "--duration", "20",
                                             "--no-rt"};
  // The words name the role needed (the program's own name says "device" too).
  ExpectRefused("snapthread-server", observer, server_args, "root key");
  ExpectRefused("snapthread-server", device, server_args, "root key");
  ExpectRefused("snapthread-device", observer, device_args, "device credential");
  ExpectRefused("snapthread-device", op, device_args, "device credential");
  ExpectRefused("snapthread-ctl", device, {"--timeout-s", "5", "status"}, "operator credential");
  ExpectRefused("snapthread-ctl", observer, {"--timeout-s", "5", "load-scene", "zeeman"}, "operator credential");
  ExpectRefused("snapthread-viewer", device, {"--print-rates", "--duration-s", "20"}, "observer credential");
#ifdef SNAPTHREAD_ROLES_TEST_WEB
  ExpectRefused("snapthread-web", device, {"--port", "0", "--duration-s", "20"}, "observer credential");
#endif
}

// The right credentials start (the refusals above are about the role, not the files).
TEST_F(WrongCredentialTest, EachProgramStartsOnItsOwnRole) {
  const std::string device = creds_->Issue(auth::Role::kDevice, "hand");
  const std::string op = creds_->Issue(auth::Role::kOperator, "console");
  auto server = StartServer(creds_->root_path());
  ASSERT_TRUE(server->running()) << server->Out();
  ASSERT_NO_FATAL_FAILURE(StartWatch());
  auto dev = StartDevice(device, "hand");
  EXPECT_TRUE(WaitForModels("hand", 30)) << dev->Out();
  const ProcessResult r = Ctl(op, {"--timeout-s", "30", "status"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("scene: curve2d_snap"), std::string::npos) << r.out;
  EXPECT_TRUE(test_support::TerminateTogether({server.get(), dev.get()}, 10.0));
}

}  // namespace
}  // namespace snapthread::roles_test
