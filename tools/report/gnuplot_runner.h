// Runs gnuplot on one script without a shell: the script is written to a private file
// (mode 0600) in the output directory and gnuplot is started with an argv (posix_spawn),
// in that directory, so no path and no text from a log is ever parsed by a shell, and the
// scripts name their data files relative to the directory.
#pragma once

#include <string>

namespace snapthread::report {

struct GnuplotRun {
  bool ok = false;       // exit status 0
  std::string problem;   // otherwise: what went wrong, for the report's notes
};

// Writes `script` to dir/<name>.gp, runs `gnuplot <name>.gp` with dir as its working
// directory, stdin from /dev/null and stdout + stderr into dir/<name>.gnuplot.log. A gnuplot
// still running after timeout_s is killed. `name` must be a plain file stem of the caller's
// own ([a-z_]+).
GnuplotRun RunGnuplotScript(const std::string& dir, const std::string& name,
                            const std::string& script, double timeout_s = 60.0);

}  // namespace snapthread::report
