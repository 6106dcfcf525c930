// The fixture of a test that runs the project's programs over udpm on loopback: the
// session key every binary inherits (SNAPTHREAD_KEY_FILE, tests/support/session_key_file.h),
// the binaries' folder, a session name of its own and a temporary directory. Header-only:
// for the test binaries that link LCM.
#pragma once

#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "environment.h"
#include "session_key_file.h"
#include "temp_dir.h"

namespace snapthread::test_support {

class ProcessSessionTest : public ::testing::Test {
 protected:
  // From SetUp(), in ASSERT_NO_FATAL_FAILURE: fails unless run through ctest (which names
  // the binaries' folder) and unless udpm starts on loopback; the session is
  // <session_prefix> made unique, the directory <dir_prefix>_<session>.
  void StartSession(const std::string& session_prefix, const std::string& dir_prefix) {
    bin_ = BinDir();
    ASSERT_FALSE(bin_.empty() || SourceDir().empty()) << "run through ctest";
    lcm::LCM probe(kLoopbackLcmUrl);
    ASSERT_TRUE(probe.good()) << "LCM udpm does not start (deploy/multicast-route.sh)";
    session_ = UniqueSession(session_prefix);
    tmp_ = std::make_unique<ScopedTempDir>(dir_prefix + "_" + session_);
  }

  const SessionKeyFile key_file_;
  std::string bin_, session_;
  std::unique_ptr<ScopedTempDir> tmp_;
};

}  // namespace snapthread::test_support
