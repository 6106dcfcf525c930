// An X display for tests that open real windows (the viewer): its own Xvfb, which picks a
// free display number itself and writes it to -displayfd once it accepts connections.
// Neither a display-number guess that races with other tests' servers nor a sleep: with
// xvfb-run -a, the number comes from lock files another server may be about to create,
// and readiness is a SIGUSR1 that can arrive before xvfb-run waits for it.
#pragma once

#include <string>
#include <vector>

#include "child_process.h"

namespace snapthread::test_support {

class VirtualDisplay {
 public:
  // Starts Xvfb with one screen of `screen` (WxHxDEPTH), its outputs in dir/xvfb.*.txt, and
  // waits up to timeout_s for it to accept connections.
  explicit VirtualDisplay(const std::string& dir, const std::string& screen = "1280x720x24",
                          double timeout_s = 30.0);
  ~VirtualDisplay();  // SIGTERM, then the kill of ChildProcess
  VirtualDisplay(const VirtualDisplay&) = delete;
  VirtualDisplay& operator=(const VirtualDisplay&) = delete;

  bool ready() const { return !display_.empty(); }
  const std::string& display() const { return display_; }  // ":N"
  // Why it is not ready: Xvfb's own output.
  std::string error() const { return xvfb_.Err(); }
  // argv that runs `command` on this display (through env DISPLAY=...).
  std::vector<std::string> On(const std::vector<std::string>& command) const;

 private:
  ChildProcess xvfb_;
  std::string display_;
};

}  // namespace snapthread::test_support
