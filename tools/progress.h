// Progress of a long run (the bench, the stability suite) for a person at a terminal: lines
// on standard error only when standard error is a terminal, nothing when it is a file, a
// pipe or a test's capture (docs/cli.md, "Progress"). Results never go through it.
#pragma once

#include <ostream>
#include <string>

namespace snapthread {

class Progress {
 public:
  // Active when standard error is a terminal (isatty).
  explicit Progress(std::string tool);
  // For tests and a forced choice.
  Progress(std::string tool, bool active) : tool_(std::move(tool)), active_(active) {}

  bool active() const { return active_; }
  // "<tool>: [done/total] what" as one line, when active.
  void Step(int done, int total, const std::string& what) const;
  // std::cerr when active, nullptr otherwise: for the functions that take an optional
  // progress stream (the bench's Run*Bench).
  std::ostream* Stream() const;

 private:
  std::string tool_;
  bool active_ = false;
};

}  // namespace snapthread
