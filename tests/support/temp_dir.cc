#include "temp_dir.h"

#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace snapthread::test_support {

std::string FreshTempDir(const std::string& name) {
  const std::string dir = "/tmp/snapthread-test-" + name + "-" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

ScopedTempDir::ScopedTempDir(const std::string& name) {
  std::string pattern = "/tmp/snapthread_" + name + "_XXXXXX";
  std::vector<char> buf(pattern.begin(), pattern.end());
  buf.push_back('\0');
  if (mkdtemp(buf.data()) == nullptr) throw std::runtime_error("mkdtemp failed for " + pattern);
  path_ = buf.data();
}

ScopedTempDir::~ScopedTempDir() {
  if (!::testing::Test::HasFailure()) {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
}

}  // namespace snapthread::test_support
