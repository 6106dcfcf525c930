#include "virtual_display.h"

#include <signal.h>

namespace snapthread::test_support {

VirtualDisplay::VirtualDisplay(const std::string& dir, const std::string& screen, double timeout_s)
    // -displayfd 1: the display number arrives in the stdout file, one line.
    : xvfb_({"Xvfb", "-displayfd", "1", "-screen", "0", screen, "-nolisten", "tcp"},
            OutputFiles(dir + "/xvfb.out.txt", dir + "/xvfb.err.txt")) {
  if (!xvfb_.started() || !xvfb_.WaitForOutput("\n", timeout_s)) return;
  std::string number = xvfb_.Out();
  number.erase(number.find('\n'));
  if (!number.empty() && number.find_first_not_of("0123456789") == std::string::npos) {
    display_ = ":" + number;
  }
}

VirtualDisplay::~VirtualDisplay() {
  xvfb_.Signal(SIGTERM);
  xvfb_.Wait(5.0);
}

std::vector<std::string> VirtualDisplay::On(const std::vector<std::string>& command) const {
  std::vector<std::string> argv = {"env", "DISPLAY=" + display_};
  argv.insert(argv.end(), command.begin(), command.end());
  return argv;
}

}  // namespace snapthread::test_support
