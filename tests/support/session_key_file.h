// A per-test session key (issue 12): a fresh 32-byte key in a temporary file of mode
// 0600, exported as SNAPTHREAD_KEY_FILE while the object lives, so the binaries a test
// starts (and the Server it constructs) use it without a --key flag.
#pragma once

#include <string>

#include "auth/session_key.h"
#include "temp_dir.h"

namespace snapthread::test_support {

class SessionKeyFile {
 public:
  SessionKeyFile();
  ~SessionKeyFile();  // restores the previous SNAPTHREAD_KEY_FILE
  SessionKeyFile(const SessionKeyFile&) = delete;
  SessionKeyFile& operator=(const SessionKeyFile&) = delete;

  const std::string& path() const { return path_; }
  const auth::SessionKey& key() const { return key_; }

 private:
  ScopedTempDir dir_{"session-key"};
  std::string path_;
  auth::SessionKey key_;
  bool had_previous_ = false;
  std::string previous_;
};

}  // namespace snapthread::test_support
