// The fixture of the role tests: a session over udpm on loopback whose programs each run
// on the key of the role they play (tests/support/role_credentials.h): snapthread-server
// on the root key, snapthread-device (simulated backend) on a device credential,
// snapthread-ctl on an operator's, snapthread-keygen on the root; and the test's own
// observer (SessionWatch) verifying with the server's public key.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "child_process.h"
#include "process_session_test.h"
#include "role_credentials.h"
#include "session_watch.h"

namespace snapthread::roles_test {

class RoleSessionTest : public test_support::ProcessSessionTest {
 protected:
  void SetUp() override;
  void TearDown() override;

  // snapthread-server on curve2d_snap (one grasp: "hand") with `key` and `extra` flags,
  // up when it has logged its session line.
  std::unique_ptr<test_support::ChildProcess> StartServer(const std::string& key,
                                                          const std::vector<std::string>& extra = {});
  // snapthread-device, sim-path backend creeping along the scene's path (no snap within
  // a test's time), its trace at dir()/<tag>_trace.csv; generous staleness so that a
  // loaded machine does not fade it.
  std::unique_ptr<test_support::ChildProcess> StartDevice(const std::string& key, const std::string& tag,
                                                          const std::vector<std::string>& extra = {});
  // Runs a program of bin_ to its end (60 s at most) with stdout and stderr apart.
  test_support::ProcessResult Run(const std::string& program, const std::vector<std::string>& args);
  // snapthread-ctl with this session's flags.
  test_support::ProcessResult Ctl(const std::string& key, const std::vector<std::string>& args);
  // snapthread-keygen on the root key.
  test_support::ProcessResult Keygen(const std::vector<std::string>& args);

  // The test's observer, trusting the root's server key now.
  void StartWatch();
  // Waits for a verified status of device `name` with models_received > 0.
  bool WaitForModels(const std::string& name, double timeout_s);

  const std::string& dir() const { return tmp_->path(); }
  std::string trace_path(const std::string& tag) const { return dir() + "/" + tag + "_trace.csv"; }

  std::unique_ptr<test_support::RoleCredentials> creds_;
  std::unique_ptr<SessionWatch> watch_;
  int runs_ = 0;
};

// Whether `text` holds `word`, ignoring case.
bool ContainsWord(const std::string& text, const std::string& word);

}  // namespace snapthread::roles_test
