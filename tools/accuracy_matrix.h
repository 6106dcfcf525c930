// The accuracy matrix (docs/accuracy.md, "Accuracy targets"): thread3d and the rod at
// several n, in two families (n unit segments; a fixed total length with the continuum
// scaling of the stiffnesses), on a hand-speed path and a large-step path. Each cell
// tracks its path at the default settings and at a round-off-polished reference
// (force_tolerance 0, cutoff 1e-11, unlimited iterations) and measures every row's force
// error, the statuses against the reference's branch, and how well the certified force
// error (SolverSummary::force_error) bounds the row's own error.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "models/model.h"
#include "models/params.h"
#include "polish.h"
#include "solvers/options.h"
#include "solvers/summary.h"

namespace snapthread {

enum class AccuracyFamily { kUnitSegments, kFixedLength };
enum class AccuracyPath { kHandSpeed, kLargeSteps };

struct AccuracyCell {
  std::string model = "thread3d";  // "thread3d" or "rod"
  AccuracyFamily family = AccuracyFamily::kUnitSegments;
  int n = 10;
  AccuracyPath path = AccuracyPath::kHandSpeed;
};

// The targets every cell is held to (fractions of the model's ForceScale()).
struct AccuracyTargets {
  double max_error = 1e-3;
  double median_error = 1e-5;
  double min_coverage = 0.99;    // share of rows with estimate >= the row's own error
  double max_median_ratio = 10;  // median estimate / the row's own error
};

// One row of a cell (all errors in model force units).
struct AccuracyRow {
  double error = 0.0, own_error = 0.0, estimate = -1.0, residual = 0.0;
  int iterations = 0;
  EquilibriumStatus status = EquilibriumStatus::kRegular, reference_status = EquilibriumStatus::kRegular;
  Termination termination = Termination::kConverged, reference_termination = Termination::kConverged;
};

struct AccuracyCellResult {
  AccuracyCell cell;
  std::vector<AccuracyRow> row_data;
  int rows = 0;
  double force_scale = 0.0;
  double segment_length = 0.0;
  // |F - F_ref|_inf / force scale over the rows (F the force part of -E_u: the grasp
  // position's components), F_ref from the reference run.
  double error_max = 0.0, error_median = 0.0;
  // The row's own error: |E_u(x) - E_u(x*)|_inf over every control (the norm of
  // force_error), x* = x polished by damped Newton steps to round-off (PolishToRoundOff).
  double own_error_max = 0.0, own_error_median = 0.0;
  // Certified force error: rows with estimate >= own error; the median estimate / own
  // error where the own error is above 1e-12 of the force scale; the rows without an
  // estimate (-1).
  int covered = 0, unestimated = 0;
  double ratio_median = 0.0, ratio_min = 0.0;
  // Against the reference run: rows whose status differs, rows whose shape is on
  // another branch (a node more than 0.1 segment lengths away).
  int status_mismatches = 0, branch_mismatches = 0;
  int snapped = 0, reference_snapped = 0, not_converged = 0, reference_not_converged = 0;
  double iterations_per_update = 0.0, reference_iterations_per_update = 0.0;
  double median_solve_us = 0.0;
  double seconds = 0.0;  // wall time of the cell (both runs and the polishing)
  bool MeetsErrorTargets(const AccuracyTargets& t) const {
    return error_max <= t.max_error && error_median <= t.median_error;
  }
  bool MeetsEstimateTargets(const AccuracyTargets& t) const {
    return unestimated == 0 && covered >= t.min_coverage * rows && ratio_median <= t.max_median_ratio;
  }
};

// The cell's model parameters: thread3d (bending 2, stretching 200 per unit segment:
// EI = beta l / 2 = 1, EA = gamma l = 200) or the rod (EI = GJ = 1, EA = 1000), with
// n segments of length 1 (total length n) or a total length L (thread3d 10, rod 1)
// in n segments, the per-segment stiffnesses scaled so the continuum is the same:
// thread3d beta = 2 EI / l, gamma = EA / l (the rod takes EI and EA as they are).
ModelParams AccuracyCellParams(const AccuracyCell& cell);
// The cell's controls: the grasp from (0.999 L, 0.5 w, 0) to (0.97 L, 0.8 w, 0.2 w) in
// 100 steps (hand speed; at w = l the path of docs/accuracy.md's "Measured") or from
// (0.999 L, 0.5 w, 0) to (0.8 L, 3 w, w) in 20 steps (large steps), w = l for unit
// segments and L / 100 for a fixed length; the rod's grasp also rolls about x, to 30
// degrees (hand speed) or 90 (large steps).
std::vector<Vec> AccuracyCellControls(const AccuracyCell& cell);


// Runs one cell with `options` (the defaults) against the reference.
AccuracyCellResult RunAccuracyCell(const AccuracyCell& cell, const SolverOptions& options = {});

std::string ToString(AccuracyFamily f);
std::string ToString(AccuracyPath p);
void WriteAccuracyMatrixCsv(const std::vector<AccuracyCellResult>& cells, std::ostream& out);
// Every row of every cell: model,family,n,path,step,error,own_error,estimate,... (errors
// relative to the force scale).
void WriteAccuracyRowsCsv(const std::vector<AccuracyCellResult>& cells, std::ostream& out);
void PrintAccuracyMatrix(const std::vector<AccuracyCellResult>& cells, const AccuracyTargets& targets,
                         std::ostream& out);

}  // namespace snapthread
