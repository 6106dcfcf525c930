// snapthread-ctl against a real snapthread-server over udpm on loopback: each subcommand
// waits for the server's authenticated answer and exits 0 when applied, 1 with the
// server's reason when refused, 3 when no authenticated answer came (another session's
// key, no server) and 2 for bad arguments. It runs as the operator: on the root key
// (operator "operator") or an operator credential; an observer's or a device's credential
// refuses to start (exit 1), naming the operator role.
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/exit_codes.h"
#include "auth/credential.h"
#include "auth/credential_file.h"
#include "process_session_test.h"
#include "session_key_file.h"
#include "test_support.h"

namespace snapthread {
namespace {

using test_support::ChildProcess;
using test_support::ProcessResult;
constexpr const char* kUrl = test_support::kLoopbackLcmUrl;

// The number after "<name>: " in `text`, or -1.
long long Field(const std::string& text, const std::string& name) {
  const size_t at = text.find(name + ": ");
  if (at == std::string::npos) return -1;
  return std::atoll(text.c_str() + at + name.size() + 2);
}

class CtlProcessTest : public test_support::ProcessSessionTest {
 protected:
  void SetUp() override { ASSERT_NO_FATAL_FAILURE(StartSession("CTL", "ctl")); }
  void TearDown() override {
    if (server_) test_support::TerminateTogether({server_.get()}, 5.0);
  }

  void StartServer() {
    const std::vector<std::string> argv{bin_ + "/snapthread-server", "--scene",
                                        test_support::ScenePath("curve2d_snap.yaml"), "--session",
                                        session_, "--lcm-url", kUrl, "--duration", "120"};
    server_ = std::make_unique<ChildProcess>(argv, test_support::OneLog(tmp_->path() + "/server.log"));
    ASSERT_TRUE(server_->started());
    ASSERT_TRUE(server_->WaitForOutput("server: session", 30)) << server_->Out();
  }

  // Runs snapthread-ctl with the session's flags and `args`; the key is the session's
  // (SNAPTHREAD_KEY_FILE) unless `args` names one.
  ProcessResult Ctl(const std::vector<std::string>& args) {
    std::vector<std::string> argv{bin_ + "/snapthread-ctl", "--session", session_, "--lcm-url", kUrl};
    argv.insert(argv.end(), args.begin(), args.end());
    const std::string out = tmp_->path() + "/ctl_" + std::to_string(++runs_);
    ChildProcess ctl(argv, test_support::OutputFiles(out + ".out", out + ".err"));
    EXPECT_TRUE(ctl.started());
    return ctl.Finish(60.0);
  }

  // A credential for `role` issued from the session's root key, in the test's directory.
  std::string Credential(auth::Role role, const std::string& name) {
    const std::string path = tmp_->path() + "/" + std::string(auth::RoleToString(role)) + "_" + name + ".cred";
    auth::WriteCredentialFile(path, auth::IssueCredential(key_file_.key(), role, name, auth::kNeverExpires),
                              false);
    return path;
  }

  std::unique_ptr<ChildProcess> server_;
  int runs_ = 0;
};

TEST_F(CtlProcessTest, ACredentialOfAnotherRoleRefusesToStartNamingTheOperator) {
  // No server needed: the console refuses before it listens.
  for (const std::string& cred : {Credential(auth::Role::kObserver, ""), Credential(auth::Role::kDevice, "hand")}) {
    const ProcessResult r = Ctl({"--key", cred, "--timeout-s", "5", "load-scene", "zeeman"});
    EXPECT_EQ(r.exit_code, app::kExitFailure) << cred << r.out << r.err;
    EXPECT_NE(r.err.find("operator"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("snapthread-ctl"), std::string::npos) << r.err;
  }
}

TEST_F(CtlProcessTest, AnOperatorCredentialLoadsTheSceneAndAnObserverChangesNothing) {
  ASSERT_NO_FATAL_FAILURE(StartServer());
  const std::string observer = Credential(auth::Role::kObserver, "");
  ProcessResult r = Ctl({"--key", observer, "load-scene", "zeeman"});
  EXPECT_NE(r.exit_code, app::kExitOk) << r.out << r.err;
  r = Ctl({"status"});
  ASSERT_EQ(r.exit_code, app::kExitOk) << r.err;
  EXPECT_NE(r.out.find("scene: curve2d_snap\n"), std::string::npos) << r.out;

  r = Ctl({"--key", Credential(auth::Role::kOperator, "alice"), "load-scene", "zeeman"});
  ASSERT_EQ(r.exit_code, app::kExitOk) << r.out << r.err;
  EXPECT_NE(r.out.find("now scene 'zeeman'"), std::string::npos) << r.out;
  r = Ctl({"status"});
  EXPECT_NE(r.out.find("scene: zeeman\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("refusals: "), std::string::npos) << r.out;
}

TEST_F(CtlProcessTest, CommandsAreAnsweredAndStatusFollowsThem) {
  ASSERT_NO_FATAL_FAILURE(StartServer());
  ProcessResult r = Ctl({"status"});
  ASSERT_EQ(r.exit_code, app::kExitOk) << r.err;
  EXPECT_NE(r.out.find("scene: curve2d_snap\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("method: "), std::string::npos) << r.out;
  EXPECT_GE(Field(r.out, "rejected messages"), 0) << r.out;

  r = Ctl({"load-scene", "zeeman"});
  ASSERT_EQ(r.exit_code, app::kExitOk) << r.out << r.err;
  EXPECT_NE(r.out.find("now scene 'zeeman'"), std::string::npos) << r.out;
  r = Ctl({"status"});
  EXPECT_NE(r.out.find("scene: zeeman\n"), std::string::npos) << r.out;

  r = Ctl({"set-method", "newton"});
  EXPECT_EQ(r.exit_code, app::kExitOk) << r.out << r.err;
  r = Ctl({"status"});
  EXPECT_NE(r.out.find("method: newton\n"), std::string::npos) << r.out;

  r = Ctl({"set-method", "bogus"});
  EXPECT_EQ(r.exit_code, app::kExitFailure) << r.out << r.err;
  EXPECT_NE(r.err.find("unknown method 'bogus'"), std::string::npos) << r.err;

  r = Ctl({"load-scene", "../zeeman"});  // scenes are names, never paths
  EXPECT_EQ(r.exit_code, app::kExitFailure) << r.out << r.err;
  EXPECT_NE(r.err.find("keeping scene 'zeeman'"), std::string::npos) << r.err;

  r = Ctl({"reset"});
  EXPECT_EQ(r.exit_code, app::kExitOk) << r.out << r.err;
  EXPECT_NE(r.out.find("start of scene 'zeeman'"), std::string::npos) << r.out;
}

TEST_F(CtlProcessTest, AnotherKeyGetsNoAnswerAndSendsNothing) {
  ASSERT_NO_FATAL_FAILURE(StartServer());
  ProcessResult before = Ctl({"status"});
  ASSERT_EQ(before.exit_code, app::kExitOk) << before.err;
  {
    // Another session's root key (acting as its operator): the server's statuses do not
    // verify under that session's server key, so the console learns no epoch, sends
    // nothing, and says why it timed out.
    test_support::SessionKeyFile other;
    const ProcessResult r = Ctl({"--key", other.path(), "--timeout-s", "1.5", "reset"});
    EXPECT_EQ(r.exit_code, app::kExitNoReply) << r.out << r.err;
    EXPECT_NE(r.err.find("--key"), std::string::npos) << r.err;
  }
  ProcessResult after = Ctl({"status"});
  ASSERT_EQ(after.exit_code, app::kExitOk) << after.err;
  EXPECT_EQ(Field(after.out, "rejected messages"), Field(before.out, "rejected messages")) << after.out;
  EXPECT_NE(after.out.find("scene: curve2d_snap\n"), std::string::npos) << after.out;
}

TEST_F(CtlProcessTest, NoServerTimesOutAndBadArgumentsExitTwo) {
  // No server on this session.
  ProcessResult r = Ctl({"--timeout-s", "0.5", "status"});
  EXPECT_EQ(r.exit_code, app::kExitNoReply) << r.out << r.err;
  EXPECT_NE(r.err.find("is a server running"), std::string::npos) << r.err;
  r = Ctl({"--timeout-s", "0.5", "set-method", "newton"});
  EXPECT_EQ(r.exit_code, app::kExitNoReply) << r.out << r.err;

  for (const std::vector<std::string>& bad :
       std::vector<std::vector<std::string>>{{},
                                             {"set-method"},
                                             {"fly"},
                                             {"--timeout-s", "nan", "status"},
                                             {"--timeout-s", "0", "status"},
                                             {"reset", "extra"}}) {
    r = Ctl(bad);
    EXPECT_EQ(r.exit_code, app::kExitUsage) << (bad.empty() ? "" : bad[0]) << r.err;
  }
  std::vector<std::string> argv{bin_ + "/snapthread-ctl", "--session", "A B", "status"};
  ChildProcess ctl(argv, test_support::OneLog(tmp_->path() + "/ctl_bad_session"));
  EXPECT_EQ(ctl.Finish(30.0).exit_code, app::kExitUsage);
}

}  // namespace
}  // namespace snapthread
