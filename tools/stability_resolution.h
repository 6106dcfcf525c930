// The stability suite at several resolutions: the knot and the rod scenes along their
// paths at several n, each method at the scene's own solver settings, and which rows
// reach no equilibrium (snapthread-stability's second table, resolution.csv).
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace snapthread {

struct ResolutionSweep {
  std::string name;        // "knot_overhand_n100"
  std::string scene_file;  // full path
  int n = 0;               // params.n
  int steps_per_leg = 0;   // the scene's path, each leg cut into this many steps
  bool name_knot = false;  // name the knot of the last row (a free rod, closed far away)
};

// knot_overhand at n = 60, 80, 100 and 150 (100 steps a leg), rod_greenhill at n = 20,
// 50 and 100 (360 steps: 2 degrees) and rod_hockling at n = 30, 60 and 100 (300 steps a
// leg, as the scene says). `scenes_dir` holds the scene files.
std::vector<ResolutionSweep> ResolutionSweeps(const std::string& scenes_dir);

struct ResolutionRow {
  std::string sweep, method;
  int n = 0;
  int rows = 0;
  int failed = 0;          // rows with status failed: no usable state
  int unconverged = 0;     // rows not converged (accuracy-limited counts as converged)
  std::string unconverged_rows;  // their numbers, runs joined: "0-8,569,619-620"
  int first_unconverged = -1;    // -1: none
  std::string last_knot;   // the knot of the last row ("" unless the sweep names it)
  int start_continuation_steps = 0;  // of the reset at row 0 (0: the direct start)
  int retried = 0;         // rows the tracker's retry (RetryFailedUpdate) solved in sub-steps
  int max_iterations = 0;  // per row
  double median_us = 0.0;  // solve time per row (update), median
  double mean_us = 0.0;    // per row
};

// Runs one sweep with `method` (the scene's other solver settings kept).
ResolutionRow RunResolution(const ResolutionSweep& sweep, const std::string& method);

// Row numbers as runs: {0, 1, 2, 5} -> "0-2,5"; "" for none.
std::string RowRuns(const std::vector<int>& rows);

void WriteResolutionCsv(const std::vector<ResolutionRow>& rows, std::ostream& out);
void PrintResolutionTable(const std::vector<ResolutionRow>& rows, std::ostream& out);

}  // namespace snapthread
