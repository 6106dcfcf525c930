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

std::map<std::string, double> ReadJsonNumbers(const std::string& path) {
  std::map<std::string, double> out;
  const std::string text = ReadFile(path);
  size_t pos = 0;
  while ((pos = text.find('"', pos)) != std::string::npos) {
    const size_t end = text.find('"', pos + 1);
    if (end == std::string::npos) break;
    const std::string key = text.substr(pos + 1, end - pos - 1);
    size_t colon = text.find_first_not_of(" \t", end + 1);
    pos = end + 1;
    if (colon == std::string::npos || text[colon] != ':') continue;
    const char* start = text.c_str() + colon + 1;
    char* stop = nullptr;
    const double v = std::strtod(start, &stop);
    if (stop != start) out[key] = v;
  }
  return out;
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
