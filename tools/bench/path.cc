// The thread3d path benchmark: the project per update, the banded LDL^T floor, Ceres.
#include "path.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "bench_support.h"
#include "linalg/linear_solver.h"
#include "models/models.h"

#ifdef SNAPTHREAD_HAVE_LAPACK
extern "C" {
void dpbtrf_(const char* uplo, const int* n, const int* kd, double* ab, const int* ldab, int* info);
void dpbtrs_(const char* uplo, const int* n, const int* kd, const int* nrhs, const double* ab, const int* ldab,
             double* b, const int* ldb, int* info);
}
#endif

namespace snapthread {
namespace {

double Microseconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::micro>(b - a).count();
}

// LAPACK's lower band storage: column j holds A(j .. j + b, j) (ab[j * (b + 1) + i - j]).
std::vector<double> LowerBand(const SparseMatrix& h, int b, double shift) {
  const int n = static_cast<int>(h.rows());
  std::vector<double> band(static_cast<size_t>(n) * (b + 1), 0.0);
  for (int j = 0; j < n; ++j)
    for (SparseMatrix::InnerIterator it(h, j); it; ++it)
      if (it.row() >= j && it.row() - j <= b) band[static_cast<size_t>(j) * (b + 1) + (it.row() - j)] = it.value();
  for (int j = 0; j < n; ++j) band[static_cast<size_t>(j) * (b + 1)] += shift;
  return band;
}

// The textbook banded LDL^T (right-looking, no pivoting, runtime bandwidth) in place
// on LowerBand storage, then one solve. False on a zero pivot.
bool PlainFactorSolve(double* ab, int n, int b, double* x) {
  const int ld = b + 1;
  for (int j = 0; j < n; ++j) {
    double* cj = ab + static_cast<size_t>(j) * ld;
    const double d = cj[0];
    if (d == 0.0 || !std::isfinite(d)) return false;
    const int m = std::min(b, n - 1 - j);
    for (int r = 1; r <= m; ++r) cj[r] /= d;  // L(j + r, j)
    for (int q = 1; q <= m; ++q) {            // A(j+r, j+q) -= L(j+r, j) d L(j+q, j)
      double* cq = ab + static_cast<size_t>(j + q) * ld;
      const double f = cj[q] * d;
      for (int r = q; r <= m; ++r) cq[r - q] -= f * cj[r];
    }
  }
  for (int j = 0; j < n; ++j) {  // L y = b
    const double* cj = ab + static_cast<size_t>(j) * ld;
    for (int r = 1, m = std::min(b, n - 1 - j); r <= m; ++r) x[j + r] -= cj[r] * x[j];
  }
  for (int j = 0; j < n; ++j) x[j] /= ab[static_cast<size_t>(j) * ld];
  for (int j = n - 1; j >= 0; --j) {  // L^T x = z
    const double* cj = ab + static_cast<size_t>(j) * ld;
    double s = 0.0;
    for (int r = 1, m = std::min(b, n - 1 - j); r <= m; ++r) s += cj[r] * x[j + r];
    x[j] -= s;
  }
  return true;
}

template <class F>
Spread TimeSamples(int samples, F&& f) {
  std::vector<double> us;
  us.reserve(samples);
  for (int k = 0; k < samples; ++k) {
    const auto t0 = Clock::now();
    f();
    us.push_back(Microseconds(t0, Clock::now()));
  }
  return Summarize(us);
}

}  // namespace

Scene Thread3dPathScene(const Scene& base, int n, const PathOptions& o) {
  Scene s = base;
  if (FindModel(s.params.model)->FindParam("grip_direction") != nullptr) s.params.Set("grip_direction", false);
  s.grasp_layout = GraspLayoutOf(s.params);
  s.params = SetChainSegments(s.params, n);
  s.name = base.name + "_path_n" + std::to_string(n);
  const double l = ChainSegmentLength(s.params);
  s.grasp_start = Vec(3);
  s.grasp_start << (n - 0.5) * l, 0.5 * l, 0.0;
  s.path = {s.grasp_start};
  s.solver.method = o.method;
  s.solver.linear_solver = o.backend;
  s.solver.cutoff = o.cutoff;
  if (o.force_tolerance >= 0.0) s.solver.force_tolerance = o.force_tolerance;
  return s;
}

std::vector<Vec> Thread3dPathControls(const Scene& scene, int steps) {
  const double l = ChainSegmentLength(scene.params);
  Vec end = scene.grasp_start;
  end[1] += 0.3 * l;
  end[2] += 0.2 * l;
  std::vector<Vec> controls;
  for (int i = 0; i <= steps; ++i) {
    controls.push_back(scene.grasp_start + (static_cast<double>(i) / steps) * (end - scene.grasp_start));
  }
  return controls;
}

bool PlainBandedSolve(const SparseMatrix& h, int bandwidth, const Vec& rhs, Vec* x) {
  std::vector<double> band = LowerBand(h, bandwidth, 0.0);
  *x = rhs;
  return PlainFactorSolve(band.data(), static_cast<int>(h.rows()), bandwidth, x->data());
}

Spread TimePlainBandedFloor(const SparseMatrix& h, int b, int samples) {
  const std::vector<double> band = LowerBand(h, b, 0.0);
  std::vector<double> work = band;
  const int n = static_cast<int>(h.rows());
  Vec x(n);
  return TimeSamples(samples, [&] {
    std::copy(band.begin(), band.end(), work.begin());
    x.setOnes();
    PlainFactorSolve(work.data(), n, b, x.data());
  });
}

Spread TimeLapackFloor(const SparseMatrix& h, int b, int samples) {
#ifdef SNAPTHREAD_HAVE_LAPACK
  // dpbtrf is a Cholesky factorisation: time it on h made positive definite (the
  // operation count does not depend on the values).
  double max_diag = 0.0;
  for (int j = 0; j < h.rows(); ++j) max_diag = std::max(max_diag, std::abs(h.coeff(j, j)));
  const std::vector<double> band = LowerBand(h, b, max_diag);
  std::vector<double> work = band;
  const int n = static_cast<int>(h.rows()), ld = b + 1, one = 1;
  Vec x(n);
  int info = 0;
  return TimeSamples(samples, [&] {
    std::copy(band.begin(), band.end(), work.begin());
    x.setOnes();
    dpbtrf_("L", &n, &b, work.data(), &ld, &info);
    dpbtrs_("L", &n, &b, &one, work.data(), &ld, x.data(), &n, &info);
  });
#else
  (void)h;
  (void)b;
  (void)samples;
  return Spread{};
#endif
}

#ifndef SNAPTHREAD_HAVE_CERES
bool CeresBuilt() { return false; }
std::vector<std::string> CeresSolverNames(int) { return {}; }
CeresPathResult RunCeresPath(const Scene&, const std::vector<Vec>&, const std::vector<Vec>&, const std::vector<Vec>&,
                             const CeresSetting&) {
  CeresPathResult r;
  r.note = "built without Ceres (deploy/setup.sh installs libceres-dev)";
  return r;
}
#endif

// The floor (plain banded LDL^T, LAPACK, the project's backend) on the Hessian at the
// tracker's last equilibrium, and the update's pieces at that state, into *row.
void TimeFloorAndPieces(const EquilibriumTracker& tracker, const PathOptions& o, PathRow* out) {
  PathRow& row = *out;
  const Model& model = tracker.model();
  SparseMatrix h = model.HessianPattern();
  model.Hessian(tracker.state(), tracker.control(), &h);
  row.unknowns = model.NumStates();
  row.bandwidth = model.HessianBandwidth();
  row.floor_us = TimePlainBandedFloor(h, row.bandwidth, o.floor_samples);
  row.lapack_us = TimeLapackFloor(h, row.bandwidth, o.floor_samples);
  {
    std::string error;
    auto backend = MakeLinearSolver("banded", row.unknowns, row.bandwidth, &error);
    backend->Analyze(h);
    Vec rhs = Vec::Ones(row.unknowns), x(row.unknowns);
    row.backend_us = TimeSamples(o.floor_samples, [&] {
      backend->Factorize(h);
      backend->Solve(rhs, &x);
    });
    // The update's pieces, at the same state.
    int b = -1;
    double* band = backend->AssemblyBand(&b);
    Vec g(row.unknowns);
    double e = 0.0;
    const BandAssemblyCapability* assembly = model.band_assembly();
    if (band != nullptr && assembly != nullptr &&
        assembly->EnergyGradientAndBandHessian(tracker.state(), tracker.control(), &g, band, b, &e)) {
      row.assembly_us = TimeSamples(o.floor_samples, [&] {
        assembly->EnergyGradientAndBandHessian(tracker.state(), tracker.control(), &g, band, b, &e);
      });
      row.factor_us = TimeSamples(o.floor_samples, [&] {
        assembly->EnergyGradientAndBandHessian(tracker.state(), tracker.control(), &g, band, b, &e);
        backend->FactorizeAssembled();
      });
      // FactorizeAssembled() alone: the pair less the assembly.
      row.factor_us.median = std::max(0.0, row.factor_us.median - row.assembly_us.median);
      row.solve_us = TimeSamples(o.floor_samples, [&] { backend->Solve(rhs, &x); });
    }
  }
}

std::vector<PathRow> RunPathBench(const std::string& scenes_dir, const PathOptions& o, std::ostream* progress) {
  const Scene base = LoadScene(scenes_dir + "/thread3d_loop.yaml");
  std::vector<PathRow> rows;
  for (int n : o.ns) {
    const Scene scene = Thread3dPathScene(base, n, o);
    const std::vector<Vec> controls = Thread3dPathControls(scene, o.steps);
    PathRow row;
    row.n = n;
    row.rows = static_cast<int>(controls.size());
    auto tracker = MakeTracker(scene);
    tracker->Reset(controls[0]);
    std::vector<Vec> states{tracker->state()}, forces{tracker->last().force};
    std::vector<double> estimates{tracker->last().summary.force_error};
    std::vector<double> us;
    long iterations = 0;
    for (size_t i = 1; i < controls.size(); ++i) {
      const auto t0 = Clock::now();
      const TrackResult& r = tracker->Update(controls[i]);
      us.push_back(Microseconds(t0, Clock::now()));
      iterations += r.summary.iterations;
      row.snaps += r.snapped ? 1 : 0;
      states.push_back(tracker->state());
      forces.push_back(r.force);
      estimates.push_back(r.summary.force_error);
    }
    row.update_us = Summarize(us);
    row.iterations_per_update = us.empty() ? 0.0 : static_cast<double>(iterations) / us.size();
    TimeFloorAndPieces(*tracker, o, &row);
    if (progress)
      *progress << "bench path: n=" << n << ": " << std::fixed << std::setprecision(2) << row.update_us.median
                << " us/update (floor " << row.floor_us.median << " us, ratio " << row.FloorRatio()
                << "; E, E_x, E_xx into the band " << row.assembly_us.median << " us, its factorisation "
                << row.factor_us.median << " us, a solve " << row.solve_us.median << " us)\n"
                << std::defaultfloat << std::flush;
    if (o.accuracy) row.accuracy = MeasurePathAccuracy(scene, controls, states, forces, estimates, o, progress);
    if (!o.ceres) {
      row.ceres.note = "not run (--no-ceres)";
    } else if (!CeresBuilt()) {
      row.ceres = RunCeresPath(scene, controls, states, forces, CeresSetting{});
    } else {
      RunCeresAccuracy(scene, controls, states, forces, o, &row, progress);
    }
    rows.push_back(row);
  }
  return rows;
}

void WritePathCsv(const std::vector<PathRow>& rows, std::ostream& out) {
  out << "n,unknowns,bandwidth,rows,update_us_median,update_us_min,update_us_max,iterations_per_update,snaps,"
         "floor_us_median,lapack_us_median,backend_us_median,floor_ratio,ceres_us_median,ceres_iterations_per_update,"
         "ceres_force_error_max,ceres_state_distance_max,ceres_rows_other_equilibrium,ceres_rows_saddle,"
         "ceres_rows_not_converged,ceres_start_on_saddle,assembly_us_median,factor_us_median,solve_us_median,"
         "ceres_equal_us_median,project_force_error_max,project_force_error_median,force_error_max,"
         "force_error_median,estimate_max,estimate_median,coverage,estimate_ratio_median,rows_over_target,"
         "reference_not_converged,coverage_resolved,rows_resolved,reference_estimate_max,reference_estimate_median,sweep_error_max,sweep_error_median\n";
  out << std::setprecision(6);
  for (const auto& r : rows) {
    const auto& c = r.ceres;
    out << r.n << ',' << r.unknowns << ',' << r.bandwidth << ',' << r.rows << ',' << r.update_us.median << ','
        << r.update_us.min << ',' << r.update_us.max << ',' << r.iterations_per_update << ',' << r.snaps << ','
        << r.floor_us.median << ',' << r.lapack_us.median << ',' << r.backend_us.median << ',' << r.FloorRatio() << ','
        << (c.ran ? c.update_us.median : 0.0) << ',' << c.iterations_per_update << ',' << c.force_error_max << ','
        << c.state_distance_max << ',' << c.rows_other_equilibrium << ',' << c.rows_saddle << ','
        << c.rows_not_converged << ',' << (c.start_on_saddle ? 1 : 0) << ',' << r.assembly_us.median << ','
        << r.factor_us.median << ',' << r.solve_us.median << ','
        << (r.ceres_equal >= 0 ? r.ceres_ladder[r.ceres_equal].update_us.median : 0.0) << ','
        << r.project_force_error_max << ',' << r.project_force_error_median << ',' << r.accuracy.error_max << ','
        << r.accuracy.error_median << ',' << r.accuracy.estimate_max << ',' << r.accuracy.estimate_median << ','
        << r.accuracy.coverage << ',' << r.accuracy.ratio_median << ',' << r.accuracy.rows_over_target << ','
        << r.accuracy.reference_not_converged << ',' << r.accuracy.coverage_resolved << ','
        << r.accuracy.rows_resolved << ',' << r.accuracy.reference_estimate_max << ','
        << r.accuracy.reference_estimate_median << ',' << r.accuracy.sweep_error_max << ','
        << r.accuracy.sweep_error_median << '\n';
  }
}

void PrintPathTable(const std::vector<PathRow>& rows, std::ostream& out, double force_target) {
  char buf[320];
  std::snprintf(buf, sizeof buf, "%6s %8s %4s %11s %8s %10s %10s %10s %8s\n", "n", "unknowns", "b", "us/update",
                "it/upd", "floor us", "LAPACK us", "banded us", "upd/flr");
  out << buf;
  for (const auto& r : rows) {
    std::snprintf(buf, sizeof buf, "%6d %8d %4d %11.2f %8.3f %10.2f %10s %10.2f %8.2f\n", r.n, r.unknowns,
                  r.bandwidth, r.update_us.median, r.iterations_per_update, r.floor_us.median,
                  r.lapack_us.count > 0 ? Sci(r.lapack_us.median, 3).c_str() : "-", r.backend_us.median,
                  r.FloorRatio());
    out << buf;
  }
  PrintPathTargets(rows, force_target, out);
  bool any_ceres = false;
  for (const auto& r : rows) any_ceres = any_ceres || r.ceres.ran;
  if (!any_ceres) {
    out << "Ceres: " << (rows.empty() ? std::string("-") : rows.front().ceres.note) << '\n';
    return;
  }
  out << "Ceres Solver side by side (same path, warm-started each row, stopped at ||E_x|| < cutoff; judged\n"
         "against the reference trace below):\n";
  std::snprintf(buf, sizeof buf, "%6s %11s %11s %8s %8s %9s %11s %8s %7s %7s %s\n", "n", "us/update", "Ceres us",
                "ratio", "it/upd", "|dF|/Fs", "max |dx|", "branch", "saddle", "unconv", "row 0");
  out << buf;
  for (const auto& r : rows) {
    const auto& c = r.ceres;
    if (!c.ran) continue;
    std::snprintf(buf, sizeof buf, "%6d %11.2f %11.2f %8.1f %8.2f %9.2e %11.3e %8d %7d %7d %s (%s)\n", r.n,
                  r.update_us.median, c.update_us.median, c.update_us.median / std::max(r.update_us.median, 1e-9),
                  c.iterations_per_update, c.force_error_max, c.state_distance_max, c.rows_other_equilibrium,
                  c.rows_saddle, c.rows_not_converged, c.start_on_saddle ? "saddle" : "minimum", c.note.c_str());
    out << buf;
  }
  PrintCeresAccuracy(rows, out);
}

std::string PathGnuplot(const std::vector<PathRow>& rows, const std::string& dir, const std::string& png) {
  {
    std::ofstream csv(dir + "/path.csv");
    WritePathCsv(rows, csv);
    std::ofstream ceres_csv(dir + "/ceres.csv");
    WriteCeresCsv(rows, ceres_csv);
  }
  const std::string file = dir + "/path.csv";
  bool lapack = false, ceres = false, ceres_equal = false;
  for (const auto& r : rows) {
    lapack = lapack || r.lapack_us.count > 0;
    ceres = ceres || r.ceres.ran;
    ceres_equal = ceres_equal || r.ceres_equal >= 0;
  }
  std::ostringstream gp;
  gp << "set terminal pngcairo size 760,560 font 'DejaVu Sans,10'\n"
     << "set output '" << png << "'\n"
     << "set termoption noenhanced\nset datafile separator ','\nset grid\nset key top left\n"
     << "set logscale x\nset logscale y\nset xlabel 'n (segments)'\nset ylabel 'median us per update'\n"
     << "set title 'thread3d path (n - 0.5, 0.5, 0) -> (n - 0.5, 0.8, 0.2), cutoff 1e-6: project, Ceres, "
        "banded LDL^T floor'\n"
     << "plot '" << file << "' every ::1 using 1:5 with linespoints pt 7 lc rgb '#2ca02c' title 'snapthread "
     << (rows.empty() ? "" : "higher-order") << " (update)'";
  if (ceres)
    gp << ", '" << file << "' every ::1 using 1:14 with linespoints pt 5 lc rgb '#d62728' title 'Ceres LM, cutoff 1e-6'";
  if (ceres_equal)
    gp << ", '" << file << "' every ::1 using 1:($25 > 0 ? $25 : 1/0) with linespoints pt 4 lc rgb '#ff7f0e' "
       << "title 'Ceres, cheapest setting at the project force accuracy'";
  gp << ", '" << file << "' every ::1 using 1:10 with linespoints pt 9 dt 2 lc rgb '#1f77b4' title 'floor: plain banded LDL^T factor + solve'";
  if (lapack)
    gp << ", '" << file << "' every ::1 using 1:11 with linespoints pt 11 dt 3 lc rgb '#9467bd' title 'LAPACK dpbtrf + dpbtrs'";
  gp << "\n";
  return gp.str();
}

}  // namespace snapthread
