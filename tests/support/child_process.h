// A program run by a test as a real child process: output captured in files, a deadline
// on every wait, and a clean kill, so a failing test never leaks processes.
#pragma once

#include <initializer_list>
#include <string>
#include <vector>

namespace snapthread::test_support {

struct ChildOptions {
  std::string out_path;  // stdout
  std::string err_path;  // stderr; empty: into out_path as well
  bool close_stdin = false;
  // The child leads its own process group, and signals and kills go to the whole group
  // (a wrapper such as xvfb-run and its children end together).
  bool own_process_group = false;
};

// stdout and stderr in one file.
ChildOptions OneLog(const std::string& path, bool close_stdin = false);
// stdout and stderr in two files.
ChildOptions OutputFiles(const std::string& out_path, const std::string& err_path, bool own_process_group = false);

// How a child ended, with what it wrote.
struct ProcessResult {
  bool exited = false;  // false: killed at the deadline
  int exit_code = -1;   // exit status, or 128 + signal
  std::string out;      // stdout
  std::string err;      // stderr
};

class ChildProcess {
 public:
  // Starts argv[0] (looked up in PATH when it has no '/'); started() tells whether it ran.
  ChildProcess(const std::vector<std::string>& argv, ChildOptions options);
  ~ChildProcess();  // SIGKILL if still running, and reaped
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  bool started() const { return pid_ > 0; }
  // Started and not yet seen to exit (polls without blocking).
  bool running();
  bool exited() const { return exited_; }
  void Signal(int sig);
  // Waits up to timeout_s for the exit; true with *code (exit status, or 128 + signal).
  // The child is left running at the deadline.
  bool Wait(double timeout_s, int* code = nullptr);
  // Wait, and at the deadline SIGTERM, grace_s later SIGKILL; false when it was killed.
  bool WaitOrKill(double timeout_s, int* code = nullptr, double grace_s = 0.0);
  // WaitOrKill, then the outputs.
  ProcessResult Finish(double timeout_s, double grace_s = 0.5);
  // Polls Out() until it contains `text`; false at the deadline or when the child exited.
  bool WaitForOutput(const std::string& text, double timeout_s);
  std::string Out() const;
  std::string Err() const;  // Out() when stderr goes to the same file

 private:
  bool Reap(bool block);
  void Kill(int sig);

  int pid_ = -1;
  bool exited_ = false;
  int code_ = -1;
  ChildOptions options_;
};

// Ends a session's processes together: SIGTERM to each at once (so the shutdown takes as
// long as the slowest, not the sum), then each waited for up to timeout_s and killed at
// the deadline (WaitOrKill). False when any had to be killed.
bool TerminateTogether(std::initializer_list<ChildProcess*> children, double timeout_s);

}  // namespace snapthread::test_support
