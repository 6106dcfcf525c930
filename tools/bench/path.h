// The thread3d path benchmark (issue 13): the n = 1000 sweep (grasp from
// (n - 0.5, 0.5, 0) to (n - 0.5, 0.8, 0.2), thread3d_loop's thread without the grip
// direction, higher-order, cutoff 1e-6) and the same path at n = 10 and 100, timed per
// update; the floor (a plain banded LDL^T factor + solve of the same size and band,
// and LAPACK's dpbtrf/dpbtrs where LAPACK is found) timed in the same run; and, where
// Ceres is found, Ceres Solver's Levenberg-Marquardt on the same energy written as
// stretching and bending residuals, warm-started each row and stopped at the same
// gradient norm.
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
  bool ceres = true;
  int floor_samples = 301;  // timed factor + solve pairs per floor
};

// Ceres Solver on the same path (ceres_path.cc).
struct CeresPathResult {
  bool ran = false;
  std::string note;                   // why it did not run, or the linear solver used
  Spread update_us;                   // per row (rows 1..steps)
  double iterations_per_update = 0.0;
  int rows_not_converged = 0;         // Ceres stopped above the cutoff
  double force_error_max = 0.0;       // max over rows |F_ceres - F_project|_inf / ForceScale
  double state_distance_max = 0.0;    // max over rows |x_ceres - x_project|_inf
  int rows_other_equilibrium = 0;     // |x_ceres - x_project|_inf > 0.1 segment lengths
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
  // (Model::EnergyGradientAndBandHessian), FactorizeAssembled() of that band, one Solve().
  // (count 0: the backend has no band, or the model does not write one)
  Spread assembly_us, factor_us, solve_us;
  CeresPathResult ceres;
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
void PrintPathTable(const std::vector<PathRow>& rows, std::ostream& out);
// Median us per update against n: the project, Ceres, the plain floor and LAPACK.
std::string PathGnuplot(const std::vector<PathRow>& rows, const std::string& csv_dir, const std::string& png);

// Ceres (ceres_path.cc; without Ceres, CeresBuilt() is false and RunCeresPath says so).
bool CeresBuilt();
// Ceres along `controls` (row 0 from the model's InitialState), compared row by row with
// the project's equilibria `states` and forces `forces` on the same rows.
CeresPathResult RunCeresPath(const Scene& scene, const std::vector<Vec>& controls, const std::vector<Vec>& states,
                             const std::vector<Vec>& forces, double cutoff);
// The Ceres problem's cost 1/2 sum r^2 at (x, u) plus the model's constant energy
// shift: equals the model's E(x, u) (the test checks it).
double CeresEnergy(const Scene& scene, const Vec& x, const Vec& u);

}  // namespace snapthread
