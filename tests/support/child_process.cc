#include "child_process.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "environment.h"

extern char** environ;

namespace snapthread::test_support {

ChildOptions OneLog(const std::string& path, bool close_stdin) { return {path, "", close_stdin, false}; }

ChildOptions OutputFiles(const std::string& out_path, const std::string& err_path, bool own_process_group) {
  return {out_path, err_path, false, own_process_group};
}

ChildProcess::ChildProcess(const std::vector<std::string>& argv, ChildOptions options)
    : options_(std::move(options)) {
  if (argv.empty()) return;
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, options_.out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (options_.err_path.empty())
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
  else
    posix_spawn_file_actions_addopen(&actions, 2, options_.err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (options_.close_stdin) posix_spawn_file_actions_addclose(&actions, 0);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  if (options_.own_process_group) {
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attr, 0);
  }
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, args[0], &actions, &attr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  pid_ = rc == 0 ? pid : -1;
}

ChildProcess::~ChildProcess() {
  if (running()) {
    Kill(SIGKILL);
    Reap(true);
  }
}

bool ChildProcess::Reap(bool block) {
  if (exited_) return true;
  int status = 0;
  const pid_t r = waitpid(pid_, &status, block ? 0 : WNOHANG);
  if (r == pid_) {
    exited_ = true;
    code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  } else if (r < 0) {
    exited_ = true;  // not our child any more (reaped elsewhere): nothing to wait for
  }
  return exited_;
}

bool ChildProcess::running() { return pid_ > 0 && !Reap(false); }

void ChildProcess::Kill(int sig) { kill(options_.own_process_group ? -pid_ : pid_, sig); }

void ChildProcess::Signal(int sig) {
  if (running()) Kill(sig);
}

bool ChildProcess::Wait(double timeout_s, int* code) {
  if (pid_ <= 0) return false;
  const bool done = WaitUntil([&] { return Reap(false); }, timeout_s, 0.01);
  if (done && code) *code = code_;
  return done;
}

bool ChildProcess::WaitOrKill(double timeout_s, int* code, double grace_s) {
  if (Wait(timeout_s, code)) return true;
  if (pid_ <= 0) return false;
  if (grace_s > 0.0) {
    Kill(SIGTERM);
    std::this_thread::sleep_for(std::chrono::duration<double>(grace_s));
  }
  Kill(SIGKILL);
  Reap(true);
  return false;
}

ProcessResult ChildProcess::Finish(double timeout_s, double grace_s) {
  ProcessResult r;
  r.exited = WaitOrKill(timeout_s, &r.exit_code, grace_s);
  r.out = Out();
  r.err = Err();
  return r;
}

bool ChildProcess::WaitForOutput(const std::string& text, double timeout_s) {
  return WaitUntil([&] { return Out().find(text) != std::string::npos || !running(); }, timeout_s, 0.02) &&
         Out().find(text) != std::string::npos;
}

std::string ChildProcess::Out() const { return ReadFile(options_.out_path); }

std::string ChildProcess::Err() const {
  return ReadFile(options_.err_path.empty() ? options_.out_path : options_.err_path);
}

bool TerminateTogether(std::initializer_list<ChildProcess*> children, double timeout_s) {
  for (ChildProcess* child : children) child->Signal(SIGTERM);
  bool all_exited = true;
  for (ChildProcess* child : children) all_exited = child->WaitOrKill(timeout_s) && all_exited;
  return all_exited;
}

}  // namespace snapthread::test_support
