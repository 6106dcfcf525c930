#include "gnuplot_runner.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>
#include <vector>

extern char** environ;

namespace snapthread::report {
namespace {

// Creates or truncates dir/file with mode 0600 (also when it existed with another mode) and
// writes `text`; refuses a symbolic link in its place.
bool WritePrivateFile(const std::string& path, const std::string& text, std::string* error) {
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) {
    *error = "cannot write " + path + ": " + std::strerror(errno);
    return false;
  }
  bool ok = fchmod(fd, 0600) == 0;
  size_t done = 0;
  while (ok && done < text.size()) {
    const ssize_t n = write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    ok = n > 0;
    if (ok) done += size_t(n);
  }
  if (close(fd) != 0) ok = false;
  if (!ok) *error = "cannot write " + path + ": " + std::strerror(errno);
  return ok;
}

}  // namespace

GnuplotRun RunGnuplotScript(const std::string& dir, const std::string& name,
                            const std::string& script, double timeout_s) {
  GnuplotRun run;
  const std::string script_file = name + ".gp";
  const std::string log_file = name + ".gnuplot.log";
  if (!WritePrivateFile(dir + "/" + script_file, script, &run.problem)) return run;

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addchdir_np(&actions, dir.c_str());
  // Opened after the chdir, so relative to dir like the script.
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_file.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW, 0600);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::vector<char*> argv = {const_cast<char*>("gnuplot"), const_cast<char*>(script_file.c_str()),
                             nullptr};
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    run.problem = std::string("cannot start gnuplot: ") + std::strerror(rc) +
                  " (install gnuplot-nox, or use --no-plots)";
    return run;
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  int status = 0;
  while (true) {
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) {
      run.problem = std::string("waitpid: ") + std::strerror(errno);
      return run;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      run.problem = "gnuplot killed after " + std::to_string(int(timeout_s)) + " s, see " + log_file;
      return run;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    run.ok = true;
  } else {
    run.problem = (WIFEXITED(status) ? "gnuplot exit " + std::to_string(WEXITSTATUS(status))
                                     : "gnuplot killed by signal " + std::to_string(WTERMSIG(status))) +
                  ", see " + log_file;
  }
  return run;
}

}  // namespace snapthread::report
