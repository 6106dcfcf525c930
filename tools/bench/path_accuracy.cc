// The path bench's accuracy at the timed settings: each row's force against its own state
// polished to round-off, the certified force error (docs/accuracy.md) against that truth,
// and the difference from an independent sweep at tight tolerances.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ostream>

#include "bench_support.h"
#include "models/registry.h"
#include "path.h"
#include "polish.h"
#include "sweep.h"

namespace snapthread {

PathAccuracy CompareWithReference(const std::vector<Vec>& forces, const std::vector<double>& estimates,
                                  const std::vector<Vec>& reference_forces, double scale, double target,
                                  const std::vector<double>& reference_estimates) {
  PathAccuracy a;
  const size_t end = std::min({forces.size(), estimates.size(), reference_forces.size()});
  std::vector<double> errors, certified, ratios;
  int covered = 0, covered_resolved = 0;
  for (size_t i = 1; i < end; ++i) {
    const double truth = (forces[i] - reference_forces[i]).lpNorm<Eigen::Infinity>() / scale;
    errors.push_back(truth);
    a.rows_over_target += truth > target ? 1 : 0;
    const bool resolved = i >= reference_estimates.size() || truth > reference_estimates[i] / scale;
    a.rows_resolved += resolved ? 1 : 0;
    if (!(estimates[i] >= 0.0)) {  // -1 (none) or NaN: no certificate, so not covered
      ++a.rows_without_estimate;
      continue;
    }
    const double estimate = estimates[i] / scale;
    certified.push_back(estimate);
    covered += estimate >= truth ? 1 : 0;
    covered_resolved += resolved && estimate >= truth ? 1 : 0;
    if (estimate > 0.0 && truth > 0.0) ratios.push_back(estimate / truth);
  }
  a.rows = static_cast<int>(errors.size());
  const Spread e = Summarize(errors), c = Summarize(certified), r = Summarize(ratios);
  a.error_max = e.max;
  a.error_median = e.median;
  a.estimate_max = c.max;
  a.estimate_median = c.median;
  a.ratio_median = r.median;
  a.coverage = a.rows > 0 ? static_cast<double>(covered) / a.rows : 0.0;
  a.coverage_resolved = a.rows_resolved > 0 ? static_cast<double>(covered_resolved) / a.rows_resolved : -1.0;
  a.ran = a.rows > 0;
  return a;
}

// The reference's force tolerance, relative to the force scale: far below the 1e-3 target
// and the default 1e-4, above the force's round-off.
constexpr double kReferenceForceTolerance = 1e-8;

PathAccuracy MeasurePathAccuracy(const Scene& scene, const std::vector<Vec>& controls, const std::vector<Vec>& states,
                                 const std::vector<Vec>& forces, const std::vector<double>& estimates,
                                 const PathOptions& o, std::ostream* progress) {
  const auto t0 = Clock::now();
  // The truth of each row: its own state polished to round-off, F = -E_u there (2.16).
  const auto model = MakeModel(scene.params);
  std::vector<Vec> polished_forces;
  Vec eu;
  for (size_t i = 0; i < controls.size() && i < states.size(); ++i) {
    model->ControlGradient(PolishToRoundOff(*model, controls[i], states[i]), controls[i], &eu);
    polished_forces.push_back(-eu);
  }
  PathAccuracy a = CompareWithReference(forces, estimates, polished_forces, model->ForceScale(), o.force_target);
  a.reference_s = Seconds(t0, Clock::now());
  // An independent sweep at the reference's tolerances: |E_x| below the reference cutoff
  // and the certified force error below kReferenceForceTolerance of the force scale, or the
  // gradient's round-off.
  Scene reference = scene;
  reference.solver.cutoff = o.reference_cutoff;
  reference.solver.force_tolerance = kReferenceForceTolerance;
  reference.solver.max_iterations = 0;
  auto tracker = MakeTracker(reference);
  const std::vector<SweepRow> rows = RunSweep(tracker.get(), controls);
  std::vector<Vec> sweep_forces;
  std::vector<double> sweep_errors, reference_certified;
  long iterations = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    sweep_forces.push_back(rows[i].force);
    if (i == 0 || i >= forces.size()) continue;
    iterations += rows[i].iterations;
    a.sweep_not_converged += rows[i].termination == Termination::kConverged ? 0 : 1;
    sweep_errors.push_back((forces[i] - rows[i].force).lpNorm<Eigen::Infinity>() / model->ForceScale());
    if (rows[i].force_error >= 0.0) reference_certified.push_back(rows[i].force_error / model->ForceScale());
  }
  const Spread se = Summarize(sweep_errors), rc = Summarize(reference_certified);
  a.sweep_error_max = se.max;
  a.sweep_error_median = se.median;
  a.reference_estimate_max = rc.max;
  a.reference_estimate_median = rc.median;
  a.reference_not_converged = a.sweep_not_converged;
  a.reference_iterations_per_update = rows.size() > 1 ? static_cast<double>(iterations) / (rows.size() - 1) : 0.0;
  if (progress)
    *progress << "bench path: " << scene.name << ": against each row polished to round-off (" << a.reference_s
              << " s): force error max " << a.error_max << ", median " << a.error_median << "; certified max "
              << a.estimate_max << ", median " << a.estimate_median << "; coverage " << 100.0 * a.coverage
              << " %, median estimate/true " << a.ratio_median << "; an independent sweep at cutoff "
              << o.reference_cutoff << " (" << a.sweep_not_converged << " rows not converged) differs by max "
              << a.sweep_error_max << ", median " << a.sweep_error_median << '\n'
              << std::flush;
  return a;
}

namespace {

const PathRow* FindN(const std::vector<PathRow>& rows, int n) {
  for (const auto& r : rows)
    if (r.n == n) return &r;
  return nullptr;
}

const char* Met(bool ok) { return ok ? "met" : "NOT met"; }

}  // namespace

void PrintPathTargets(const std::vector<PathRow>& rows, double force_target, std::ostream& out) {
  char buf[400];
  bool any_accuracy = false;
  for (const auto& r : rows) any_accuracy = any_accuracy || r.accuracy.ran;
  if (any_accuracy) {
    out << "Accuracy at the timed settings: force error = |F - F_ref|_inf / force scale over rows 1..steps, F_ref\n"
           "= -E_u at the row's own state polished to round-off by damped Newton steps (the model and a\n"
           "linear solver only); certified = the update's own estimate (SolverSummary::force_error) /\n"
           "force scale; coverage = rows with certified >= true; ref s = the polishing's time; sweep =\n"
           "an independent sweep at cutoff 1e-11 and force tolerance 1e-8: its difference max / median\n"
           "(where the valley floor is flat to round-off it settles elsewhere on it), its own certified\n"
           "error max and its rows not converged:\n";
    std::snprintf(buf, sizeof buf, "%6s %10s %10s %10s %10s %10s %10s %9s %9s %8s %10s %10s %10s %8s\n", "n",
                  "us/update", "floor us", "err max", "err med", "cert max", "cert med", "coverage", "cert/true",
                  "ref s", "sweep mx", "sweep md", "sweep cert", "unconv");
    out << buf;
    for (const auto& r : rows) {
      const PathAccuracy& a = r.accuracy;
      if (!a.ran) continue;
      std::snprintf(buf, sizeof buf,
                    "%6d %10.2f %10.2f %10.2e %10.2e %10.2e %10.2e %8.1f%% %9.2f %8.1f %10.2e %10.2e %10.2e %8d\n",
                    r.n, r.update_us.median, r.floor_us.median, a.error_max, a.error_median, a.estimate_max,
                    a.estimate_median, 100.0 * a.coverage, a.ratio_median, a.reference_s, a.sweep_error_max,
                    a.sweep_error_median, a.reference_estimate_max, a.sweep_not_converged);
      out << buf;
    }
  }
  out << "Targets (medians of this run):\n";
  const PathRow* r10 = FindN(rows, 10);
  const PathRow* r100 = FindN(rows, 100);
  const PathRow* r1000 = FindN(rows, 1000);
  if (r10) {
    std::snprintf(buf, sizeof buf, "  n = 10: %.2f us per update (target <= 5) -> %s\n", r10->update_us.median,
                  Met(r10->update_us.median <= 5.0));
    out << buf;
  }
  if (r100) {
    std::snprintf(buf, sizeof buf, "  n = 100: %.2f us per update (target <= 25) -> %s\n", r100->update_us.median,
                  Met(r100->update_us.median <= 25.0));
    out << buf;
  }
  if (r1000) {
    std::snprintf(buf, sizeof buf,
                  "  n = 1000: update / plain banded LDL^T floor = %.2f (target <= 1.5) -> %s; / LAPACK floor = %s\n",
                  r1000->FloorRatio(), Met(r1000->FloorRatio() <= 1.5),
                  r1000->lapack_us.count > 0 ? Sci(r1000->update_us.median / r1000->lapack_us.median, 3).c_str() : "-");
    out << buf;
  }
  if (r100 && r1000 && r100->update_us.median > 0) {
    const double exponent = std::log10(r1000->update_us.median / r100->update_us.median);
    std::snprintf(buf, sizeof buf, "  growth exponent n = 100 -> 1000: %.3f (target <= 1.02) -> %s\n", exponent,
                  Met(exponent <= 1.02));
    out << buf;
  }
  for (const auto& r : rows) {
    const PathAccuracy& a = r.accuracy;
    if (!a.ran) continue;
    std::snprintf(buf, sizeof buf,
                  "  n = %d: every row's force error <= %.0e of the force scale: max %.2e, %d of %d rows over -> %s; "
                  "certified >= true on %.1f %% of rows (target >= 99 %%), median certified / true %.2f "
                  "(target <= 10) -> %s\n",
                  r.n, force_target, a.error_max, a.rows_over_target, a.rows, Met(a.rows_over_target == 0),
                  100.0 * a.coverage, a.ratio_median, Met(a.coverage >= 0.99 && a.ratio_median <= 10.0));
    out << buf;
  }
}

}  // namespace snapthread
