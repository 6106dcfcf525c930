#include "progress.h"

#include <unistd.h>

#include <iostream>

namespace snapthread {

Progress::Progress(std::string tool) : tool_(std::move(tool)), active_(isatty(STDERR_FILENO) == 1) {}

void Progress::Step(int done, int total, const std::string& what) const {
  if (!active_) return;
  std::cerr << tool_ << ": [" << done << '/' << total << "] " << what << '\n' << std::flush;
}

std::ostream* Progress::Stream() const { return active_ ? &std::cerr : nullptr; }

}  // namespace snapthread
