#include "environment.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

namespace snapthread::test_support {

namespace {
std::string EnvOr(const char* name, const char* fallback) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? v : fallback;
}
}  // namespace

std::string SourceDir() { return EnvOr("SNAPTHREAD_SOURCE_DIR", SNAPTHREAD_TEST_SOURCE_DIR); }
std::string BinDir() { return EnvOr("SNAPTHREAD_BIN_DIR", SNAPTHREAD_TEST_BIN_DIR); }
std::string ScenePath(const std::string& file) { return SourceDir() + "/scenes/" + file; }

double SpeedScale() {
  const char* v = std::getenv("SNAPTHREAD_SPEED_SCALE");
  if (v == nullptr || *v == '\0') return 1.0;
  char* end = nullptr;
  const double scale = std::strtod(v, &end);
  return (end != v && *end == '\0' && scale >= 1.0 && scale <= 100.0) ? scale : 1.0;
}

std::string UniqueSession(const std::string& prefix) {
  static std::atomic<int> counter{0};
  std::random_device rd;
  return prefix + "_" + std::to_string(getpid()) + "_" + std::to_string(counter++) + "_" +
         std::to_string(rd() % 100000);
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

bool WaitUntil(const std::function<bool()>& condition, double timeout_s, double poll_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < deadline) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::duration<double>(poll_s));
  }
  return condition();
}

bool WaitForFile(const std::string& path, double timeout_s) {
  return WaitUntil(
      [&] {
        std::error_code ec;
        return std::filesystem::file_size(path, ec) > 0 && !ec;
      },
      timeout_s, 0.02);
}

}  // namespace snapthread::test_support
