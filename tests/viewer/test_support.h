// Helpers for the viewer/report tests: run a binary as a real process with a deadline,
// read PNGs back, unique session names, paths from the ctest environment.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace snapthread::viewer_test {

struct ProcessResult {
  bool exited = false;  // false: killed at the deadline
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

// Starts argv[0] (PATH lookup) with stdout/stderr captured into files; returns its pid.
int StartProcess(const std::vector<std::string>& argv, const std::string& out_path,
                 const std::string& err_path);
// Waits up to timeout_s for pid; kills its process group when late.
ProcessResult WaitProcess(int pid, double timeout_s, const std::string& out_path,
                          const std::string& err_path);
bool ProcessRunning(int pid);

struct Image {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;  // top row first
  const uint8_t* At(int x, int y) const { return &rgb[(size_t(y) * width + x) * 3]; }
};
// Reads an 8-bit PNG (any colour type, converted to RGB). False with *error when invalid.
bool ReadPng(const std::string& path, Image* image, std::string* error);

std::string UniqueSession(const std::string& prefix);
std::string BinDir();     // $SNAPTHREAD_BIN_DIR
std::string SourceDir();  // $SNAPTHREAD_SOURCE_DIR
std::string TempDir(const std::string& name);  // fresh directory under /tmp
std::string ReadFile(const std::string& path);

}  // namespace snapthread::viewer_test
