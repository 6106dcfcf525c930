#include "role_session.h"

#include <algorithm>
#include <cctype>

#include "auth/role_keys.h"
#include "environment.h"

namespace snapthread::roles_test {

using test_support::ChildProcess;
using test_support::ProcessResult;

bool ContainsWord(const std::string& text, const std::string& word) {
  auto lower = [](std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
    return s;
  };
  return lower(text).find(lower(word)) != std::string::npos;
}

void RoleSessionTest::SetUp() {
  ASSERT_NO_FATAL_FAILURE(StartSession("RL", "roles"));
  creds_ = std::make_unique<test_support::RoleCredentials>("roles_keys");
}

void RoleSessionTest::TearDown() { watch_.reset(); }

std::unique_ptr<ChildProcess> RoleSessionTest::StartServer(const std::string& key,
                                                           const std::vector<std::string>& extra) {
  std::vector<std::string> argv{bin_ + "/snapthread-server", "--key", key, "--scene",
                                test_support::ScenePath("curve2d_snap.yaml"), "--session", session_,
                                "--lcm-url", test_support::kLoopbackLcmUrl, "--duration", "120",
                                "--log-level", "info"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  auto server = std::make_unique<ChildProcess>(argv, test_support::OneLog(dir() + "/server.log", true));
  EXPECT_TRUE(server->started());
  EXPECT_TRUE(server->WaitForOutput("server: session", 30)) << server->Out();
  return server;
}

std::unique_ptr<ChildProcess> RoleSessionTest::StartDevice(const std::string& key, const std::string& tag,
                                                           const std::vector<std::string>& extra) {
  std::vector<std::string> argv{bin_ + "/snapthread-device", "--key", key, "--backend", "sim-path",
                                "--scene", test_support::ScenePath("curve2d_snap.yaml"),
                                "--speed-m-per-s", "0.004", "--session", session_, "--lcm-url",
                                test_support::kLoopbackLcmUrl, "--duration", "120", "--rate-hz", "1000",
                                "--publish-divisor", "1", "--no-rt", "--trace", trace_path(tag),
                                "--summary", dir() + "/" + tag + ".json"};
  // A test may shorten the staleness (the revocation test).
  if (std::find(extra.begin(), extra.end(), "--model-timeout-ms") == extra.end()) {
    // Staleness is about speed: scaled for a slower build (SNAPTHREAD_SPEED_SCALE).
    argv.insert(argv.end(), {"--model-timeout-ms", std::to_string(static_cast<int>(400 * test_support::SpeedScale())),
                             "--fade-ms", "100"});
  }
  argv.insert(argv.end(), extra.begin(), extra.end());
  auto device = std::make_unique<ChildProcess>(argv, test_support::OneLog(dir() + "/" + tag + ".log", true));
  EXPECT_TRUE(device->started());
  return device;
}

ProcessResult RoleSessionTest::Run(const std::string& program, const std::vector<std::string>& args) {
  std::vector<std::string> argv{bin_ + "/" + program};
  argv.insert(argv.end(), args.begin(), args.end());
  const std::string out = dir() + "/" + program + "_" + std::to_string(++runs_);
  ChildProcess child(argv, test_support::OutputFiles(out + ".out", out + ".err"));
  EXPECT_TRUE(child.started());
  return child.Finish(60.0);
}

ProcessResult RoleSessionTest::Ctl(const std::string& key, const std::vector<std::string>& args) {
  std::vector<std::string> all{"--key", key, "--session", session_, "--lcm-url", test_support::kLoopbackLcmUrl};
  all.insert(all.end(), args.begin(), args.end());
  return Run("snapthread-ctl", all);
}

ProcessResult RoleSessionTest::Keygen(const std::vector<std::string>& args) {
  std::vector<std::string> all{"--key", creds_->root_path()};
  all.insert(all.end(), args.begin(), args.end());
  return Run("snapthread-keygen", all);
}

void RoleSessionTest::StartWatch() {
  watch_ = std::make_unique<SessionWatch>(session_, test_support::kLoopbackLcmUrl,
                                          std::vector<auth::PublicKey>{auth::DeriveServerPublicKey(creds_->Root())});
  ASSERT_TRUE(watch_->good());
}

bool RoleSessionTest::WaitForModels(const std::string& name, double timeout_s) {
  return test_support::WaitUntil(
      [&] {
        const auto d = watch_->device(name);
        return d && d->models_received > 0;
      },
      timeout_s, 0.05);
}

}  // namespace snapthread::roles_test
