// The stability suite: standard sweeps where methods fail (seed Figs 2.5, 2.7, 2.10,
// 3.5), each run per method and iteration budget and compared with a reference trace.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "sweep.h"

namespace snapthread {

struct StandardSweep {
  std::string name;         // e.g. "zeeman_folds"
  std::string scene_file;   // relative to the source tree's scenes/
  std::string description;
  std::vector<Vec> controls;  // full control vectors, row by row
  int force_component = 0;    // the force component charted
  double step = 0.0;          // control distance per row (model units / radians)
};

// The standard sweeps of the issue: zeeman across its folds and looping around the
// cusp both ways; cusp through and around (0,0); curve2d_snap up and down; thread3d
// loop formation; the rod's Greenhill buckle. `scenes_dir` is the folder holding the scene files.
std::vector<StandardSweep> StandardSweeps(const std::string& scenes_dir);

struct StabilityRow {
  std::string sweep;
  std::string method;  // a registered solver name
  int budget = 0;              // iterations per update, 0 = unlimited
  int reversals = 0;           // sign changes of successive force differences (all components)
  int reference_reversals = 0;
  int spurious_reversals = 0;  // max(0, reversals - reference_reversals)
  int snaps = 0, reference_snaps = 0;
  int snap_error_steps = 0;    // max |row - reference row| over reference snaps (-1: one missed)
  int extra_snaps = 0;         // snaps with no reference snap within one step
  double force_error_max = 0.0, force_error_rms = 0.0;  // |F - F_ref|, model units
  double state_error_max = 0.0;  // |probe - probe_ref|
  double mean_gradients = 0.0, mean_hessians = 0.0, mean_us = 0.0;  // per update
};

// Reference: newton-ls, cutoff 1e-10, `max_iterations` per update (0 = unlimited),
// `substeps` fine steps between rows (only the rows are kept; a row is snapped when any
// fine step since the previous row snapped).
std::vector<SweepRow> ReferenceTrace(const Scene& scene, const std::vector<Vec>& controls, int substeps,
                                     int max_iterations = 0);

// Compares a trace with the reference trace of the same rows.
StabilityRow Compare(const std::vector<SweepRow>& trace, const std::vector<SweepRow>& ref);

// Reversals of the force trace (sign changes of successive differences, ignoring
// moves smaller than `tolerance`) of one component; all components summed when
// component < 0.
int CountReversals(const std::vector<SweepRow>& rows, int component, double tolerance);
// 1e-3 of the reference trace's force range: chatter is far larger, cutoff noise far smaller.
double ReversalTolerance(const std::vector<SweepRow>& ref);

void WriteStabilityCsv(const std::vector<StabilityRow>& rows, std::ostream& out);
void PrintStabilityTable(const std::vector<StabilityRow>& rows, std::ostream& out);

}  // namespace snapthread
