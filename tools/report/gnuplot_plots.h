// PNG plots of a session review, drawn by gnuplot (gnuplot-nox, pngcairo terminal) from the
// CSV files SessionReview::WriteCsv wrote into the same directory.
#pragma once

#include <string>
#include <vector>

#include "session_review.h"

namespace snapthread::report {

struct PlotOutcome {
  std::vector<std::string> written;  // PNG file names
  std::vector<std::string> notes;    // plots skipped (no data) or failed, and why
};

// Writes <name>.gp scripts (mode 0600) into `dir` and runs `gnuplot` on each without a shell
// (gnuplot_runner.h); `gnuplot` must be on PATH. No text of the log reaches a script but a
// session name of the session grammar.
PlotOutcome MakePlots(const std::string& dir, const SessionReview& review);

}  // namespace snapthread::report
