#include "test_support.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include <png.h>

extern char** environ;

namespace snapthread::viewer_test {

int StartProcess(const std::vector<std::string>& argv, const std::string& out_path,
                 const std::string& err_path) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  // Own process group, so a late process and its children (Xvfb) are killed together.
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, args[0], &actions, &attr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  return rc == 0 ? pid : -1;
}

bool ProcessRunning(int pid) {
  int status = 0;
  return waitpid(pid, &status, WNOHANG) == 0;
}

ProcessResult WaitProcess(int pid, double timeout_s, const std::string& out_path,
                          const std::string& err_path) {
  ProcessResult r;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  int status = 0;
  while (true) {
    const pid_t w = waitpid(pid, &status, WNOHANG);
    if (w == pid) {
      r.exited = true;
      r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      break;
    }
    if (w < 0) break;
    if (std::chrono::steady_clock::now() > deadline) {
      kill(-pid, SIGTERM);
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      kill(-pid, SIGKILL);
      waitpid(pid, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  r.out = ReadFile(out_path);
  r.err = ReadFile(err_path);
  return r;
}

bool ReadPng(const std::string& path, Image* image, std::string* error) {
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, path.c_str())) {
    *error = std::string("not a readable PNG: ") + img.message;
    return false;
  }
  img.format = PNG_FORMAT_RGB;
  image->width = int(img.width);
  image->height = int(img.height);
  image->rgb.assign(PNG_IMAGE_SIZE(img), 0);
  if (!png_image_finish_read(&img, nullptr, image->rgb.data(), 0, nullptr)) {
    *error = std::string("PNG decode failed: ") + img.message;
    png_image_free(&img);
    return false;
  }
  return true;
}

std::string UniqueSession(const std::string& prefix) {
  std::random_device rd;
  return prefix + "_" + std::to_string(getpid()) + "_" + std::to_string(rd() % 1000000);
}

std::string BinDir() {
  const char* d = std::getenv("SNAPTHREAD_BIN_DIR");
  return d ? d : ".";
}

std::string SourceDir() {
  const char* d = std::getenv("SNAPTHREAD_SOURCE_DIR");
  return d ? d : ".";
}

std::string TempDir(const std::string& name) {
  const std::string dir = "/tmp/snapthread-test-" + name + "-" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace snapthread::viewer_test
