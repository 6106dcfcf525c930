// The thread3d path benchmark: the n = 1000 hand-speed sweep (grasp from
// (n - 0.5, 0.5, 0) to (n - 0.5, 0.8, 0.2), thread3d_loop's thread without the grip
// direction, higher-order, cutoff 1e-6) and the same path at n = 10 and 100, timed per
// update; the floor (a plain banded LDL^T factor + solve of the same size and band,
// and LAPACK's dpbtrf/dpbtrs where LAPACK is found) timed in the same run; and, where
// Ceres is found, Ceres Solver on the same energy written as stretching and bending
// residuals, warm-started each row and stopped at a gradient norm: at the project's
// cutoff, and down a ladder of tighter ones until its forces are as accurate as the
// project's against a Newton-polished reference (ceres_accuracy.cc).
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "bench.h"

namespace snapthread {

struct PathOptions {
  std::vector<int> ns = {10, 100, 1000};
  int steps = 1000;
  std::string method = "higher-order";
  std::string backend = "auto";
  double cutoff = 1e-6;
  // solver.force_tolerance of the timed run; < 0: the default (SolverOptions, 1e-4).
  double force_tolerance = -1.0;
  bool ceres = true;
  int floor_samples = 301;  // timed factor + solve pairs per floor
  // Equal force accuracy (the project against Ceres, each at its own best settings):
  // the reference trace is the project's rows, each polished by Newton steps while
  // ||E_x|| falls (ceres_accuracy.cc); Ceres runs at cutoff 10^-k cutoff,
  // k = 0 .. ceres_ladder - 1, with each of CeresSolverNames(n), until its force error
  // against the reference (max and median over the rows) is <= the project's.
  int ceres_ladder = 6;
  double ceres_time_limit_s = 60.0;  // per Ceres setting and n (a cut-off path is not "equal")
  // The accuracy at the timed settings (path_accuracy.cc): every row's force against a
  // reference, the same path at reference_cutoff with no force tolerance and no iteration
  // limit (each row ends converged at round-off), and the certified estimate against it.
  bool accuracy = true;
  double reference_cutoff = 1e-11;
  // The accuracy targets: every row's force error <= force_target of the force scale.
  double force_target = 1e-3;
};

// The project's forces on the path against the round-off-polished reference, relative to
// the model's ForceScale(), over rows 1..steps.
struct PathAccuracy {
  bool ran = false;
  int rows = 0;                        // rows compared
  double reference_s = 0.0;            // wall time of the reference sweep
  int reference_not_converged = 0;     // reference rows not ending `converged`
  double reference_iterations_per_update = 0.0;
  double error_max = 0.0, error_median = 0.0;        // true: |F - F_ref|_inf / ForceScale
  double estimate_max = 0.0, estimate_median = 0.0;  // certified (SolverSummary::force_error) / ForceScale
  int rows_without_estimate = 0;       // force_error -1 (counted as not covering)
  double coverage = 0.0;               // fraction of rows with estimate >= true error
  // The same over the rows whose true error exceeds the reference's own certified error
  // (elsewhere the difference is the reference's round-off, not the row's error); -1: none.
  double coverage_resolved = -1.0;
  int rows_resolved = 0;
  double ratio_median = 0.0;           // median estimate / true over rows with both > 0
  int rows_over_target = 0;            // true error > PathOptions::force_target
  // The reference's own certified error / ForceScale over rows 1..steps: how exact the truth is.
  double reference_estimate_max = 0.0, reference_estimate_median = 0.0;
  // The same path solved again at the reference's tolerances (an independent sweep):
  // |F - F_sweep|_inf / ForceScale. Where the valley floor is flat to round-off (n = 1000)
  // the sweep settles on another point of it, so this measures path dependence within
  // round-off, not the row's error.
  double sweep_error_max = 0.0, sweep_error_median = 0.0;
  int sweep_not_converged = 0;
};
// The statistics of PathAccuracy from the per-row forces, certified estimates (model
// units, -1 = none) and reference forces (rows 1..end; row 0, the reset, is left out).
// reference_estimates: the reference rows' certified errors (model units; empty: unknown).
PathAccuracy CompareWithReference(const std::vector<Vec>& forces, const std::vector<double>& estimates,
                                  const std::vector<Vec>& reference_forces, double force_scale, double force_target,
                                  const std::vector<double>& reference_estimates = {});
// Compares each row with the reference: its own state polished to round-off by damped
// Newton steps (PolishToRoundOff: the model and a linear solver only, independent of the
// solvers), and with an independent sweep at the reference's tolerances; one line of
// progress when `progress` is set.
PathAccuracy MeasurePathAccuracy(const Scene& scene, const std::vector<Vec>& controls, const std::vector<Vec>& states,
                                 const std::vector<Vec>& forces, const std::vector<double>& estimates,
                                 const PathOptions& options, std::ostream* progress = nullptr);

// One Ceres run: a trust-region strategy and linear solver (CeresSolverNames) and the
// ||E_x||_2 cutoff that stops each row.
struct CeresSetting {
  std::string solver = "lm-sparse-cholmod";
  double cutoff = 1e-6;
  int max_iterations = 400;   // per row
  double time_limit_s = 0.0;  // > 0: stop the path once Ceres' solves have taken this long
};

// Ceres Solver on the same path (ceres_path.cc), judged row by row against given
// equilibria and forces (the project's, or the reference trace's).
struct CeresPathResult {
  bool ran = false;
  std::string note;                   // why it did not run, or the setting
  std::string solver;
  double cutoff = 0.0;
  Spread update_us;                   // per row (rows 1..steps)
  double iterations_per_update = 0.0;
  int rows_not_converged = 0;         // Ceres did not reach the cutoff (iteration limit, failure)
  double force_error_max = 0.0;       // over rows |F_ceres - F_given|_inf / ForceScale
  double force_error_median = 0.0;
  double state_distance_max = 0.0;    // max over rows |x_ceres - x_given|_inf
  int rows_other_equilibrium = 0;     // |x_ceres - x_given|_inf > 0.1 segment lengths
  int stopped_at_row = 0;             // > 0: the time limit ended the path at this row
  int rows_saddle = 0;                // E_xx at Ceres' state has a negative pivot
  bool start_on_saddle = false;       // row 0 (from the model's initial state)
  int start_negative_pivots = 0;      // of E_xx at Ceres' row 0 (-1: singular)
  double start_state_distance = 0.0;
};

struct PathRow {
  int n = 0;
  int unknowns = 0;
  int bandwidth = 0;
  int rows = 0;
  Spread update_us;                   // project, per update
  double iterations_per_update = 0.0;
  int snaps = 0;
  Spread floor_us;                    // plain banded LDL^T factor + solve
  Spread lapack_us;                   // LAPACK dpbtrf + dpbtrs (count 0: not built)
  Spread backend_us;                  // the project's own backend: Factorize + Solve
  // Where an update's time goes, timed at the last row's state with the update's own
  // pieces: the model's E, E_x and E_xx written into the banded backend's band
  // (BandAssemblyCapability), FactorizeAssembled() of that band, one Solve().
  // (count 0: the backend has no band, or the model does not write one)
  Spread assembly_us, factor_us, solve_us;
  CeresPathResult ceres;  // the first Ceres setting at the project's cutoff
  // Equal force accuracy: the reference trace's ||E_x||_2 (max, median over rows
  // 1..steps), how far polishing moved the project's states, and the project's force
  // error against it (over rows 1..steps, |F - F_ref|_inf / ForceScale); every Ceres
  // setting run, judged against the reference; the index of the fastest one whose max
  // and median force errors are both <= the project's (-1: none).
  double reference_gradient_max = 0.0, reference_gradient_median = 0.0, reference_moved_max = 0.0;
  double project_force_error_max = 0.0, project_force_error_median = 0.0;
  std::vector<CeresPathResult> ceres_ladder;
  int ceres_equal = -1;
  PathAccuracy accuracy;  // at the timed settings, against the cutoff-1e-11 reference
  double FloorRatio() const { return floor_us.median > 0 ? update_us.median / floor_us.median : 0.0; }
};

// thread3d_loop's thread with n segments, no grip direction, grasp at (n - 0.5, 0.5, 0).
Scene Thread3dPathScene(const Scene& thread3d_base, int n, const PathOptions& options);
// Rows 0..steps from (n - 0.5, 0.5, 0) to (n - 0.5, 0.8, 0.2) in equal steps.
std::vector<Vec> Thread3dPathControls(const Scene& scene, int steps);

// Median time of a plain banded LDL^T factor + one solve of h (band storage filled from
// h's lower triangle, no pivoting, runtime bandwidth: the textbook right-looking loop),
// and of LAPACK's dpbtrf + dpbtrs on h shifted to be positive definite (count 0 when
// the bench is built without LAPACK).
Spread TimePlainBandedFloor(const SparseMatrix& h, int bandwidth, int samples);
Spread TimeLapackFloor(const SparseMatrix& h, int bandwidth, int samples);
// The textbook factor + solve itself (for the test: it must solve the system).
bool PlainBandedSolve(const SparseMatrix& h, int bandwidth, const Vec& rhs, Vec* x);

std::vector<PathRow> RunPathBench(const std::string& scenes_dir, const PathOptions& options, std::ostream* progress);
void WritePathCsv(const std::vector<PathRow>& rows, std::ostream& out);
void PrintPathTable(const std::vector<PathRow>& rows, std::ostream& out, double force_target = 1e-3);
// The accuracy table (PathAccuracy per n, next to the speed) and every target of the run
// (speed at n = 10, 100, 1000, growth exponent, every row's force error <= force_target,
// the estimate's coverage), each met or not.
void PrintPathTargets(const std::vector<PathRow>& rows, double force_target, std::ostream& out);
// Median us per update against n: the project, Ceres, the plain floor and LAPACK.
std::string PathGnuplot(const std::vector<PathRow>& rows, const std::string& csv_dir, const std::string& png);

// Ceres (ceres_path.cc; without Ceres, CeresBuilt() is false and RunCeresPath says so).
bool CeresBuilt();
// Ceres along `controls` (row 0 from the model's InitialState), compared row by row with
// the given equilibria `states` and forces `forces` on the same rows.
CeresPathResult RunCeresPath(const Scene& scene, const std::vector<Vec>& controls, const std::vector<Vec>& states,
                             const std::vector<Vec>& forces, const CeresSetting& setting);
// The Ceres settings tried at n segments, the first the default (Ceres' own advice).
std::vector<std::string> CeresSolverNames(int n);
// Whether a whole Ceres run's force error (max and median over the rows) is <= the project's.
bool CeresMatchesAccuracy(const PathRow& row, const CeresPathResult& c);
void WriteCeresCsv(const std::vector<PathRow>& rows, std::ostream& out);
// ceres_accuracy.cc: from the project's equilibria `states` and forces `forces`, the
// reference trace, the project's force error against it and the Ceres ladder into *row;
// the table and verdict for them.
void RunCeresAccuracy(const Scene& scene, const std::vector<Vec>& controls, const std::vector<Vec>& states,
                      const std::vector<Vec>& forces,
                      const PathOptions& o, PathRow* row, std::ostream* progress);
void PrintCeresAccuracy(const std::vector<PathRow>& rows, std::ostream& out);
// The Ceres problem's cost 1/2 sum r^2 at (x, u) plus the model's constant energy
// shift: equals the model's E(x, u) (the test checks it).
double CeresEnergy(const Scene& scene, const Vec& x, const Vec& u);

}  // namespace snapthread
