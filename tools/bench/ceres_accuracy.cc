// "10x faster than Ceres at equal force accuracy", decided on the thread3d
// path: a reference trace (the project's tracker at a tight cutoff, each row polished by
// Newton to round-off), the project's force error against it, and Ceres Solver down a
// ladder of cutoffs per setting until its force error (max and median over the rows)
// is no larger than the project's; the time ratio at the cheapest such setting.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <string>

#include "models/models.h"
#include "path.h"
#include "polish.h"

namespace snapthread {

bool CeresMatchesAccuracy(const PathRow& row, const CeresPathResult& c) {
  // Force accuracy is what counts: rows where Ceres did not reach its cutoff are
  // reported (unconv), not held against it.
  return c.ran && c.stopped_at_row == 0 && c.force_error_max <= row.project_force_error_max &&
         c.force_error_median <= row.project_force_error_median;
}

namespace {

// The reference trace: each of the project's equilibria polished by damped Newton steps
// until ||E_x||_2 stops falling (12 failed steps in a row, at most 200 steps), i.e. the
// exact equilibrium next to it, down to the round-off of E_x. (A second tracker at
// cutoff 1e-12 with undamped, backtracked polishing was tried first: it left n = 1000
// rows at ||E_x|| up to 3.7e-8 on the 1000-step path and 5.9e-7 on a 100-step one.)
struct PolishedTrace {
  std::vector<Vec> states, forces;
  double gradient_max = 0.0, gradient_median = 0.0;
  double moved_max = 0.0;  // max over rows |x_ref - x_project|_inf
};

PolishedTrace MakePolishedTrace(const Scene& scene, const std::vector<Vec>& controls,
                                const std::vector<Vec>& states) {
  const auto model = MakeModel(scene.params);
  PolishedTrace ref;
  std::vector<double> gradients;
  Vec g, eu;
  for (size_t i = 0; i < controls.size(); ++i) {
    const Vec& u = controls[i];
    // Damped so that a step along the softest mode (lambda_min ~1e-11 at n = 1000, far
    // beyond where E_x is linear) does not stall the polish (tools/polish.h).
    const Vec x = PolishToRoundOff(*model, u, states[i]);
    model->Gradient(x, u, &g);
    model->ControlGradient(x, u, &eu);
    ref.moved_max = std::max(ref.moved_max, (x - states[i]).lpNorm<Eigen::Infinity>());
    ref.states.push_back(x);
    ref.forces.push_back(-eu);
    if (i > 0) gradients.push_back(g.norm());
  }
  const Spread spread = Summarize(gradients);
  ref.gradient_max = spread.max;
  ref.gradient_median = spread.median;
  return ref;
}

// The Ceres side: the reference trace, the project's force error against it, and
// the Ceres settings, each solver down the cutoff ladder until it matches the project.
}  // namespace

void RunCeresAccuracy(const Scene& scene, const std::vector<Vec>& controls, const std::vector<Vec>& states,
                      const std::vector<Vec>& forces, const PathOptions& o, PathRow* row, std::ostream* progress) {
  const PolishedTrace ref = MakePolishedTrace(scene, controls, states);
  const auto model = MakeModel(scene.params);
  std::vector<double> errors;
  for (size_t i = 1; i < controls.size(); ++i)
    errors.push_back((forces[i] - ref.forces[i]).lpNorm<Eigen::Infinity>() / model->ForceScale());
  const Spread e = Summarize(errors);
  row->reference_gradient_max = ref.gradient_max;
  row->reference_gradient_median = ref.gradient_median;
  row->reference_moved_max = ref.moved_max;
  row->project_force_error_max = e.max;
  row->project_force_error_median = e.median;
  if (progress)
    *progress << "bench path: n=" << row->n << " reference (the project's rows Newton-polished): ||E_x|| max "
              << ref.gradient_max << ", median " << ref.gradient_median << ", moved <= " << ref.moved_max
              << "; project's force error max " << e.max << ", median " << e.median << " of the force scale\n"
              << std::flush;
  int first_equal_k = -1;
  const std::vector<std::string> solvers = CeresSolverNames(row->n);
  for (size_t s = 0; s < solvers.size(); ++s) {
    // The first solver walks the whole ladder; the others start one rung looser than
    // where the first matched (the cheaper rungs cannot do better than their own).
    const int k0 = (s == 0 || first_equal_k < 0) ? 0 : std::max(0, first_equal_k - 1);
    for (int k = k0; k < o.ceres_ladder; ++k) {
      CeresSetting setting;
      setting.solver = solvers[s];
      setting.cutoff = o.cutoff * std::pow(10.0, -k);
      setting.time_limit_s = o.ceres_time_limit_s;
      CeresPathResult c = RunCeresPath(scene, controls, ref.states, ref.forces, setting);
      if (!c.ran) {
        row->ceres.note = c.note;
        return;
      }
      const bool equal = CeresMatchesAccuracy(*row, c);
      if (progress)
        *progress << "bench path: n=" << row->n << " Ceres " << c.solver << " cutoff " << c.cutoff << ": "
                  << c.update_us.median << " us/update, " << c.iterations_per_update << " it/update, force error max "
                  << c.force_error_max << " median " << c.force_error_median << ", unconverged " << c.rows_not_converged
                  << (c.stopped_at_row > 0 ? ", time limit at row " + std::to_string(c.stopped_at_row) : std::string())
                  << (equal ? " -> equal accuracy" : "") << '\n' << std::flush;
      if (s == 0 && k == 0) row->ceres = c;
      row->ceres_ladder.push_back(c);
      if (equal) {
        const int index = static_cast<int>(row->ceres_ladder.size()) - 1;
        if (row->ceres_equal < 0 || c.update_us.median < row->ceres_ladder[row->ceres_equal].update_us.median)
          row->ceres_equal = index;
        if (s == 0) first_equal_k = k;
        break;
      }
      // A path cut by the time limit only gets slower further down the ladder, and a
      // cutoff that most rows cannot reach (Ceres' steps stall on round-off in the
      // cost) stalls at every tighter one.
      if (c.stopped_at_row > 0 || 2 * c.rows_not_converged > row->rows) break;
    }
  }
}

void WriteCeresCsv(const std::vector<PathRow>& rows, std::ostream& out) {
  out << "n,solver,cutoff,ceres_us_median,ceres_iterations_per_update,force_error_max,force_error_median,"
         "rows_not_converged,stopped_at_row,rows_other_equilibrium,rows_saddle,state_distance_max,"
         "project_us_median,project_force_error_max,project_force_error_median,reference_gradient_max,"
         "equal_accuracy,max_only_equal,ratio\n";
  out << std::setprecision(6);
  for (const auto& r : rows) {
    for (const auto& c : r.ceres_ladder) {
      const bool max_only = c.ran && c.stopped_at_row == 0 && c.force_error_max <= r.project_force_error_max;
      out << r.n << ',' << c.solver << ',' << c.cutoff << ',' << c.update_us.median << ',' << c.iterations_per_update
          << ',' << c.force_error_max << ',' << c.force_error_median << ',' << c.rows_not_converged << ','
          << c.stopped_at_row << ',' << c.rows_other_equilibrium << ',' << c.rows_saddle << ','
          << c.state_distance_max << ',' << r.update_us.median << ',' << r.project_force_error_max << ','
          << r.project_force_error_median << ',' << r.reference_gradient_max << ','
          << (CeresMatchesAccuracy(r, c) ? 1 : 0) << ',' << (max_only ? 1 : 0) << ','
          << c.update_us.median / std::max(r.update_us.median, 1e-9) << '\n';
    }
  }
}


// The equal-accuracy part of the table: every Ceres setting run, then the verdict.
void PrintCeresAccuracy(const std::vector<PathRow>& rows, std::ostream& out) {
  char buf[400];
  out << "Equal force accuracy: reference = the project's equilibria, each Newton-polished to\n"
         "round-off; force error = |F - F_ref|_inf / force scale over rows 1..steps; Ceres down a\n"
         "ladder of cutoffs per setting until max and median are both <= the project's:\n";
  std::snprintf(buf, sizeof buf, "%6s %14s %14s %14s %13s %13s\n", "n", "ref |E_x| max", "ref |E_x| med",
                "polish moved", "project max", "project med");
  out << buf;
  for (const auto& r : rows) {
    if (r.ceres_ladder.empty()) continue;
    std::snprintf(buf, sizeof buf, "%6d %14.2e %14.2e %14.2e %13.2e %13.2e\n", r.n, r.reference_gradient_max,
                  r.reference_gradient_median, r.reference_moved_max, r.project_force_error_max,
                  r.project_force_error_median);
    out << buf;
  }
  std::snprintf(buf, sizeof buf, "%6s %-22s %8s %11s %8s %10s %10s %7s %7s %7s %6s %s\n", "n", "Ceres setting",
                "cutoff", "Ceres us", "it/upd", "err max", "err med", "unconv", "branch", "saddle", "ratio", "equal");
  out << buf;
  for (const auto& r : rows) {
    for (const auto& c : r.ceres_ladder) {
      std::snprintf(buf, sizeof buf, "%6d %-22s %8.0e %11.1f %8.2f %10.2e %10.2e %7d %7d %7d %6.1f %s%s\n", r.n,
                    c.solver.c_str(), c.cutoff, c.update_us.median, c.iterations_per_update, c.force_error_max,
                    c.force_error_median, c.rows_not_converged, c.rows_other_equilibrium, c.rows_saddle,
                    c.update_us.median / std::max(r.update_us.median, 1e-9),
                    CeresMatchesAccuracy(r, c) ? "yes" : "no",
                    c.stopped_at_row > 0 ? (" (time limit at row " + std::to_string(c.stopped_at_row) + ")").c_str()
                                         : "");
      out << buf;
    }
  }
  out << "  >= 10x faster than Ceres at equal force accuracy (target):\n";
  for (const auto& r : rows) {
    if (r.ceres_ladder.empty()) continue;
    // Ceres-favourable reading too: only the worst row has to match.
    const CeresPathResult* max_only = nullptr;
    const CeresPathResult* closest = nullptr;
    for (const auto& c : r.ceres_ladder) {
      if (c.stopped_at_row == 0 && c.force_error_max <= r.project_force_error_max &&
          (!max_only || c.update_us.median < max_only->update_us.median))
        max_only = &c;
      if (!closest || c.force_error_max < closest->force_error_max) closest = &c;
    }
    const double p = std::max(r.update_us.median, 1e-9);
    if (r.ceres_equal >= 0) {
      const auto& c = r.ceres_ladder[r.ceres_equal];
      std::snprintf(buf, sizeof buf,
                    "  n = %d: cheapest equal setting %s at cutoff %.0e: %.1f us / %.2f us = %.1fx -> %s", r.n,
                    c.solver.c_str(), c.cutoff, c.update_us.median, r.update_us.median, c.update_us.median / p,
                    c.update_us.median / p >= 10.0 ? "met" : "NOT met");
    } else {
      std::snprintf(buf, sizeof buf,
                    "  n = %d: no Ceres setting reaches the project's accuracy (closest in max: %s at %.0e, err max "
                    "%.2e, median %.2e, %.1f us = %.1fx) -> met",
                    r.n, closest->solver.c_str(), closest->cutoff, closest->force_error_max,
                    closest->force_error_median, closest->update_us.median, closest->update_us.median / p);
    }
    out << buf;
    if (max_only) {
      std::snprintf(buf, sizeof buf, "; max-only criterion: %s at %.0e, %.1fx", max_only->solver.c_str(),
                    max_only->cutoff, max_only->update_us.median / p);
      out << buf;
    }
    out << '\n';
  }
}


}  // namespace snapthread
