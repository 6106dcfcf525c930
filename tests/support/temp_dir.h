// Temporary directories for a test's logs, scenes and outputs.
#pragma once

#include <string>

namespace snapthread::test_support {

// A fresh directory /tmp/snapthread-test-<name>-<pid> (emptied if it existed).
std::string FreshTempDir(const std::string& name);

// A unique directory made with mkdtemp, removed at the end of a passing test and kept
// for the post-mortem of a failing one.
class ScopedTempDir {
 public:
  explicit ScopedTempDir(const std::string& name = "test");
  ~ScopedTempDir();
  ScopedTempDir(const ScopedTempDir&) = delete;
  ScopedTempDir& operator=(const ScopedTempDir&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace snapthread::test_support
