#include "accuracy_matrix.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <numbers>
#include <string>

#include "linalg/linear_solver.h"
#include "models/registry.h"
#include "tracking/tracker.h"

namespace snapthread {
namespace {

// Total length of the fixed-length family: thread3d 10 (so its n = 10 member is the unit
// thread of the other family), the rod 1 (its scenes').
double FixedLength(const AccuracyCell& c) { return c.model == "rod" ? 1.0 : 10.0; }

double TotalLength(const AccuracyCell& c) {
  return c.family == AccuracyFamily::kUnitSegments ? static_cast<double>(c.n) : FixedLength(c);
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// One tracked run of the cell's path: per row the summary, the state, the full -E_u and
// the node positions.
struct Run {
  std::vector<SolverSummary> summaries;
  std::vector<Vec> states, forces;
  std::vector<Eigen::Matrix3Xd> nodes;
  std::vector<bool> snapped;
};

// Tracks `controls` with `options`; with `polish`, *own_error gets each row's
// |E_u(x) - E_u(x*)|_inf against the row's state polished to round-off.
Run Track(const AccuracyCell& cell, const std::vector<Vec>& controls, const SolverOptions& options,
          std::vector<double>* own_error) {
  const ModelParams params = AccuracyCellParams(cell);
  EquilibriumTracker tracker(MakeModel(params), options);
  const double l = TotalLength(cell) / cell.n;
  tracker.SetSnapThreshold(0.1 * l);
  const Model& model = tracker.model();
  Run run;
  Vec eu;
  for (size_t i = 0; i < controls.size(); ++i) {
    const TrackResult& r = i == 0 ? tracker.Reset(controls[i]) : tracker.Update(controls[i]);
    run.summaries.push_back(r.summary);
    run.states.push_back(tracker.state());
    run.forces.push_back(r.force);
    run.snapped.push_back(i > 0 && r.snapped);
    Eigen::Matrix3Xd nodes;
    model.NodePositions(tracker.state(), controls[i], &nodes);
    run.nodes.push_back(std::move(nodes));
    if (own_error != nullptr) {
      const Vec ref = PolishToRoundOff(model, controls[i], tracker.state());
      model.ControlGradient(ref, controls[i], &eu);
      own_error->push_back((r.force + eu).lpNorm<Eigen::Infinity>());
    }
  }
  return run;
}

// The row-by-row comparison of the run with the reference and with its own polished rows.
void Compare(const Run& run, const Run& ref, const std::vector<double>& own_error, AccuracyCellResult* out) {
  const double scale = out->force_scale;
  std::vector<double> errors, own, ratios;
  double its = 0.0, ref_its = 0.0;
  std::vector<double> us;
  out->ratio_min = 1e300;
  for (size_t i = 0; i < run.forces.size(); ++i) {
    const SolverSummary& s = run.summaries[i];
    const SolverSummary& rs = ref.summaries[i];
    errors.push_back((run.forces[i].head(3) - ref.forces[i].head(3)).lpNorm<Eigen::Infinity>() / scale);
    own.push_back(own_error[i] / scale);
    if (s.force_error < 0.0) {
      ++out->unestimated;
    } else {
      if (s.force_error >= own_error[i]) ++out->covered;
      if (own_error[i] > 1e-12 * scale) ratios.push_back(s.force_error / own_error[i]);
    }
    out->row_data.push_back({errors.back() * scale, own_error[i], s.force_error, s.residual, s.iterations, s.status,
                             rs.status, s.termination, rs.termination});
    if (s.status != rs.status) ++out->status_mismatches;
    const double apart = (run.nodes[i] - ref.nodes[i]).cwiseAbs().maxCoeff();
    if (apart > 0.1 * out->segment_length) ++out->branch_mismatches;
    out->snapped += run.snapped[i];
    out->reference_snapped += ref.snapped[i];
    out->not_converged += !s.IsConverged();
    out->reference_not_converged += !rs.IsConverged();
    if (i > 0) {
      its += s.iterations;
      ref_its += rs.iterations;
      us.push_back(s.solve_us);
    }
  }
  const double updates = std::max<double>(1.0, static_cast<double>(run.forces.size()) - 1.0);
  out->rows = static_cast<int>(run.forces.size());
  out->error_max = *std::max_element(errors.begin(), errors.end());
  out->error_median = Median(errors);
  out->own_error_max = *std::max_element(own.begin(), own.end());
  out->own_error_median = Median(own);
  out->ratio_median = Median(ratios);
  for (double r : ratios) out->ratio_min = std::min(out->ratio_min, r);
  if (ratios.empty()) out->ratio_min = 0.0;
  out->iterations_per_update = its / updates;
  out->reference_iterations_per_update = ref_its / updates;
  out->median_solve_us = Median(us);
}

}  // namespace

ModelParams AccuracyCellParams(const AccuracyCell& cell) {
  const double length = TotalLength(cell);
  const double l = length / cell.n;
  ModelParams p;
  p.model = cell.model;
  p.Set("n", cell.n);
  if (cell.model == "rod") {
    // The rod takes continuum stiffnesses (per edge EI / l and EA / l, docs/models-rod.md).
    p.Set("length", length);
    p.Set("stretch_stiffness", 1000.0);
    p.Set("bend_stiffness", 1.0);
    p.Set("bend_stiffness_2", 1.0);
    p.Set("twist_stiffness", 1.0);
    return p;
  }
  // thread3d: beta/2 (1 - cos phi) ~ beta/4 phi^2 = EI/(2 l) phi^2 and
  // gamma/2 (l_i - l)^2 = EA/(2 l) (l_i - l)^2: beta = 2 EI / l, gamma = EA / l, with
  // EI = 1, EA = 200 (the unit thread's bending 2, stretching 200).
  p.Set("segment_length", l);
  p.Set("bending", 2.0 * 1.0 / l);
  p.Set("stretching", 200.0 / l);
  return p;
}

std::vector<Vec> AccuracyCellControls(const AccuracyCell& cell) {
  const double length = TotalLength(cell);
  const double w = cell.family == AccuracyFamily::kUnitSegments ? 1.0 : length / 100.0;
  const bool hand = cell.path == AccuracyPath::kHandSpeed;
  const int steps = hand ? 100 : 20;
  const Eigen::Vector3d from(0.999 * length, 0.5 * w, 0.0);
  const Eigen::Vector3d to = hand ? Eigen::Vector3d(0.97 * length, 0.8 * w, 0.2 * w)
                                  : Eigen::Vector3d(0.8 * length, 3.0 * w, 1.0 * w);
  const double roll = (hand ? 30.0 : 90.0) * std::numbers::pi / 180.0;
  const bool rod = cell.model == "rod";
  std::vector<Vec> us;
  for (int i = 0; i <= steps; ++i) {
    const double t = static_cast<double>(i) / steps;
    Vec u = Vec::Zero(rod ? 6 : 3);
    u.head(3) = from + t * (to - from);
    if (rod) u[3] = t * roll;  // the rotation vector: a roll about x
    us.push_back(u);
  }
  return us;
}

Vec PolishToRoundOff(const Model& model, const Vec& u, Vec x) {
  const int n = model.NumStates();
  std::string error;
  auto solver = MakeLinearSolver("auto", n, model.HessianBandwidth(), &error);
  SparseMatrix h = model.HessianPattern();
  if (!solver || solver->Analyze(h) != LinearSolverStatus::kSuccess) return x;
  Vec g(n), dx(n), trial(n), gt(n);
  model.Gradient(x, u, &g);
  double mu = 0.0;
  int refused = 0;
  for (int it = 0; it < 200 && refused < 12; ++it) {
    model.Hessian(x, u, &h);
    for (int k = 0; k < h.outerSize(); ++k)
      for (SparseMatrix::InnerIterator e(h, k); e; ++e)
        if (e.row() == e.col()) e.valueRef() += mu;
    if (solver->Factorize(h) != LinearSolverStatus::kSuccess || solver->Solve(g, &dx) != LinearSolverStatus::kSuccess) {
      mu = std::max(mu * 10.0, 1e-12);
      ++refused;
      continue;
    }
    trial = x - dx;
    model.Gradient(trial, u, &gt);
    if (gt.allFinite() && gt.norm() < g.norm()) {
      x.swap(trial);
      g.swap(gt);
      mu /= 100.0;
      refused = 0;
    } else {
      mu = std::max(mu * 10.0, 1e-12);
      ++refused;
    }
  }
  return x;
}

AccuracyCellResult RunAccuracyCell(const AccuracyCell& cell, const SolverOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  AccuracyCellResult out;
  out.cell = cell;
  out.force_scale = MakeModel(AccuracyCellParams(cell))->ForceScale();
  out.segment_length = TotalLength(cell) / cell.n;
  const std::vector<Vec> controls = AccuracyCellControls(cell);
  std::vector<double> own_error;
  const Run run = Track(cell, controls, options, &own_error);
  SolverOptions ref_options = options;
  ref_options.force_tolerance = 0.0;
  ref_options.cutoff = 1e-11;
  ref_options.max_iterations = 0;
  const Run ref = Track(cell, controls, ref_options, nullptr);
  Compare(run, ref, own_error, &out);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

std::string ToString(AccuracyFamily f) { return f == AccuracyFamily::kUnitSegments ? "unit" : "fixed-L"; }
std::string ToString(AccuracyPath p) { return p == AccuracyPath::kHandSpeed ? "hand" : "large"; }

void WriteAccuracyMatrixCsv(const std::vector<AccuracyCellResult>& cells, std::ostream& out) {
  out << "model,family,n,path,rows,force_scale,error_max,error_median,own_error_max,own_error_median,"
         "covered,unestimated,ratio_median,ratio_min,status_mismatches,branch_mismatches,snapped,"
         "reference_snapped,not_converged,reference_not_converged,iterations_per_update,"
         "reference_iterations_per_update,median_solve_us,seconds\n";
  out << std::setprecision(6);
  for (const AccuracyCellResult& c : cells) {
    out << c.cell.model << ',' << ToString(c.cell.family) << ',' << c.cell.n << ',' << ToString(c.cell.path) << ','
        << c.rows << ',' << c.force_scale << ',' << c.error_max << ',' << c.error_median << ',' << c.own_error_max
        << ',' << c.own_error_median << ',' << c.covered << ',' << c.unestimated << ',' << c.ratio_median << ','
        << c.ratio_min << ',' << c.status_mismatches << ',' << c.branch_mismatches << ',' << c.snapped << ','
        << c.reference_snapped << ',' << c.not_converged << ',' << c.reference_not_converged << ','
        << c.iterations_per_update << ',' << c.reference_iterations_per_update << ',' << c.median_solve_us << ','
        << c.seconds << '\n';
  }
}

void WriteAccuracyRowsCsv(const std::vector<AccuracyCellResult>& cells, std::ostream& out) {
  out << "model,family,n,path,step,error,own_error,estimate,residual,iterations,status,reference_status,"
         "termination,reference_termination\n";
  out << std::setprecision(6);
  for (const AccuracyCellResult& c : cells) {
    for (size_t i = 0; i < c.row_data.size(); ++i) {
      const AccuracyRow& r = c.row_data[i];
      out << c.cell.model << ',' << ToString(c.cell.family) << ',' << c.cell.n << ',' << ToString(c.cell.path) << ','
          << i << ',' << r.error / c.force_scale << ',' << r.own_error / c.force_scale << ','
          << r.estimate / c.force_scale << ',' << r.residual << ',' << r.iterations << ',' << ToString(r.status) << ','
          << ToString(r.reference_status) << ',' << ToString(r.termination) << ',' << ToString(r.reference_termination)
          << '\n';
    }
  }
}

void PrintAccuracyMatrix(const std::vector<AccuracyCellResult>& cells, const AccuracyTargets& t,
                         std::ostream& out) {
  out << "| model | family | n | path | error max | median | own max | covered | est/own median | "
         "status / branch differ | snapped (ref) | it/update (ref) | targets |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const AccuracyCellResult& c : cells) {
    const bool errors = c.MeetsErrorTargets(t), estimate = c.MeetsEstimateTargets(t);
    out << std::setprecision(2) << "| " << c.cell.model << " | " << ToString(c.cell.family) << " | " << c.cell.n
        << " | " << ToString(c.cell.path) << " | " << c.error_max << " | " << c.error_median << " | "
        << c.own_error_max << " | " << c.covered << "/" << c.rows << " | " << c.ratio_median << " | "
        << c.status_mismatches << " / " << c.branch_mismatches << " | " << c.snapped << " (" << c.reference_snapped
        << ") | " << std::setprecision(3) << c.iterations_per_update << " (" << c.reference_iterations_per_update
        << ") | " << (errors ? "error ok" : "ERROR") << ", " << (estimate ? "estimate ok" : "ESTIMATE") << " |\n";
  }
}

}  // namespace snapthread
