// Accuracy chart: speed against force error per method / cutoff / budget, Pareto fronts.
#include "bench_support.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "models/models.h"

namespace snapthread {

namespace fs = std::filesystem;

std::vector<int> ParetoFront(const std::vector<ParetoPoint>& p) {
  std::vector<int> front;
  for (size_t i = 0; i < p.size(); ++i) {
    bool dominated = false;
    for (size_t j = 0; j < p.size() && !dominated; ++j) {
      if (i == j) continue;
      const bool no_worse = p[j].rate_hz >= p[i].rate_hz && p[j].error <= p[i].error;
      const bool better = p[j].rate_hz > p[i].rate_hz || p[j].error < p[i].error;
      // An exact duplicate earlier in the list dominates later copies.
      dominated = no_worse && (better || j < i);
    }
    if (!dominated) front.push_back(static_cast<int>(i));
  }
  std::sort(front.begin(), front.end(), [&](int a, int b) { return p[a].rate_hz < p[b].rate_hz; });
  return front;
}

// ---------------------------------------------------------------- accuracy

double RegularRowsForceError(const std::vector<SweepRow>& trace, const std::vector<SweepRow>& ref, double scale) {
  const int n = static_cast<int>(std::min(trace.size(), ref.size()));
  std::vector<char> near(n, 0);
  for (int i = 0; i < n; ++i)
    if (trace[i].snapped || ref[i].snapped)
      for (int k = std::max(0, i - kSnapMargin); k <= std::min(n - 1, i + kSnapMargin); ++k) near[k] = 1;
  double sum2 = 0.0;
  int count = 0;
  for (int i = 0; i < n; ++i)
    if (!near[i]) {
      sum2 += (trace[i].force - ref[i].force).squaredNorm();
      ++count;
    }
  return count > 0 ? std::sqrt(sum2 / count) / scale : 0.0;
}

namespace {

// One point of the chart: `scene` (its solver set) timed along `controls` and judged
// against the reference trace `ref`.
AccuracyRow MeasureAccuracyRow(const std::string& sweep, const Scene& scene, const std::vector<Vec>& controls,
                               const std::vector<SweepRow>& ref, double scale, const AccuracyOptions& o) {
  const TimedSweep t = TimeSweep(scene, controls, o.repetitions, o.min_time_s);
  AccuracyRow row;
  row.sweep = sweep;
  row.method = scene.solver.method;
  row.cutoff = scene.solver.cutoff;
  row.budget = scene.solver.max_iterations;
  row.force_tolerance = scene.solver.force_tolerance;
  row.rate_hz = t.rate_hz;
  row.force_scale = scale;
  row.stability = Compare(t.rows, ref);
  row.force_error_rel_rms_regular = RegularRowsForceError(t.rows, ref, scale);
  row.stability.sweep = sweep;
  row.stability.method = row.method;
  row.stability.budget = row.budget;
  double sum2 = 0.0;
  int count = 0;
  for (const SweepRow& r : t.rows) {
    if (!(r.force_error >= 0.0)) {
      ++row.rows_without_estimate;
      continue;
    }
    const double e = r.force_error / scale;
    sum2 += e * e;
    row.certified_rel_max = std::max(row.certified_rel_max, e);
    ++count;
  }
  row.certified_rel_rms = count > 0 ? std::sqrt(sum2 / count) : 0.0;
  return row;
}

}  // namespace

std::vector<AccuracyRow> RunAccuracyBench(const std::string& scenes_dir, const AccuracyOptions& o,
                                          std::ostream* progress) {
  std::vector<AccuracyRow> out;
  const auto all = StandardSweeps(scenes_dir);
  for (const std::string& name : o.sweeps) {
    const StandardSweep* sw = nullptr;
    for (const auto& s : all)
      if (s.name == name) sw = &s;
    if (!sw) throw std::invalid_argument("bench: no standard sweep named '" + name + "'");
    const Scene scene = LoadScene(sw->scene_file);
    const double scale = ForceScaleOf(scene);
    const auto t_ref = Clock::now();
    const auto ref = ReferenceTrace(scene, sw->controls, o.substeps);
    if (progress)
      *progress << "bench accuracy: " << name << ": " << sw->controls.size() << " updates, reference in "
                << std::fixed << std::setprecision(1) << Seconds(t_ref, Clock::now()) << " s\n"
                << std::defaultfloat << std::flush;
    const size_t first = out.size();
    for (const std::string& m : o.methods) {
      const auto t_m = Clock::now();
      for (double cutoff : o.cutoffs)
        for (int budget : o.budgets) {
          Scene sc = WithSolver(scene, m, cutoff, budget);
          sc.solver.force_tolerance = 0.0;  // the cutoff alone, as snapthread-sweep --cutoff
          out.push_back(MeasureAccuracyRow(name, sc, sw->controls, ref, scale, o));
        }
      // The default settings: the scene's cutoff (a ceiling) and budget, stopping on the force.
      Scene defaults = scene;
      defaults.solver.method = m;
      defaults.solver.force_tolerance = SolverOptions{}.force_tolerance;
      out.push_back(MeasureAccuracyRow(name, defaults, sw->controls, ref, scale, o));
      out.back().default_settings = true;
      if (progress)
        *progress << "bench accuracy: " << name << " " << m << " (" << o.cutoffs.size() * o.budgets.size()
                  << " configurations + the default x " << o.repetitions << ") in " << std::fixed
                  << std::setprecision(1) << Seconds(t_m, Clock::now()) << " s\n"
                  << std::defaultfloat << std::flush;
    }
    std::vector<AccuracyRow> part(out.begin() + first, out.end());
    MarkParetoFronts(&part);
    std::copy(part.begin(), part.end(), out.begin() + first);
  }
  return out;
}

void MarkParetoFronts(std::vector<AccuracyRow>* rows) {
  std::map<std::string, std::vector<int>> by_sweep;
  for (size_t i = 0; i < rows->size(); ++i) by_sweep[(*rows)[i].sweep].push_back(static_cast<int>(i));
  for (const auto& [name, idx] : by_sweep) {
    std::vector<ParetoPoint> pts;
    for (int i : idx) pts.push_back({(*rows)[i].rate_hz.median, (*rows)[i].RelativeForceErrorRms()});
    for (int i : idx) (*rows)[i].pareto = false;
    for (int k : ParetoFront(pts)) (*rows)[idx[k]].pareto = true;
  }
}

void WriteAccuracyCsv(const std::vector<AccuracyRow>& rows, std::ostream& out) {
  out << "sweep,method,cutoff,budget,rate_hz_median,rate_hz_min,rate_hz_max,repetitions,force_scale,"
         "force_error_rms,force_error_max,force_error_rel_rms,state_error_max,spurious_reversals,reversals,"
         "reference_reversals,snaps,reference_snaps,snap_error_steps,gradients_per_update,hessians_per_update,pareto,"
         "force_error_rel_rms_away_from_snaps,force_tolerance,default_settings,certified_rel_rms,certified_rel_max,"
         "rows_without_estimate\n";
  out << std::setprecision(6);
  for (const auto& r : rows) {
    const StabilityRow& s = r.stability;
    out << r.sweep << ',' << r.method << ',' << r.cutoff << ',' << r.budget << ',' << r.rate_hz.median << ','
        << r.rate_hz.min << ',' << r.rate_hz.max << ',' << r.rate_hz.count << ',' << r.force_scale << ','
        << s.force_error_rms << ',' << s.force_error_max << ',' << r.RelativeForceErrorRms() << ','
        << s.state_error_max << ',' << s.spurious_reversals << ',' << s.reversals << ',' << s.reference_reversals
        << ',' << s.snaps << ',' << s.reference_snaps << ',' << s.snap_error_steps << ',' << s.mean_gradients << ','
        << s.mean_hessians << ',' << (r.pareto ? 1 : 0) << ',' << r.force_error_rel_rms_regular << ','
        << r.force_tolerance << ',' << (r.default_settings ? 1 : 0) << ',' << r.certified_rel_rms << ','
        << r.certified_rel_max << ',' << r.rows_without_estimate << '\n';
  }
}

void PrintAccuracyTable(const std::vector<AccuracyRow>& rows, bool pareto_only, std::ostream& out) {
  char buf[320];
  std::snprintf(buf, sizeof buf, "%-14s %-12s %7s %6s %11s %17s %10s %10s %10s %10s %8s %9s %7s %6s\n", "sweep",
                "method", "cutoff", "budget", "rate(1/s)", "rate min..max", "|dF|/Fs", "certified", "off-snap",
                "|dx|max", "chatter", "snap_err", "grad/up", "front");
  out << buf;
  for (const auto& r : rows) {
    if (pareto_only && !r.pareto) continue;
    const StabilityRow& s = r.stability;
    const std::string snap = s.snap_error_steps < 0 ? "missed" : std::to_string(s.snap_error_steps);
    const std::string span = Sci(r.rate_hz.min, 1) + ".." + Sci(r.rate_hz.max, 1);
    const std::string cutoff = r.default_settings ? "default" : Sci(r.cutoff, 0);
    std::snprintf(buf, sizeof buf, "%-14s %-12s %7s %6s %11.3e %17s %10.2e %10.2e %10.2e %10.2e %8d %9s %7.2f %6s\n",
                  r.sweep.c_str(), r.method.c_str(), cutoff.c_str(), BudgetText(r.budget).c_str(), r.rate_hz.median,
                  span.c_str(), r.RelativeForceErrorRms(), r.certified_rel_rms, r.force_error_rel_rms_regular,
                  s.state_error_max,
                  s.spurious_reversals, snap.c_str(),
                  s.mean_gradients, r.pareto ? "*" : "");
    out << buf;
  }
}

std::string ParetoGnuplot(const std::vector<AccuracyRow>& rows, const std::string& dir, const std::string& png) {
  std::vector<std::string> sweeps;
  std::vector<std::string> methods;
  for (const auto& r : rows) {
    if (std::find(sweeps.begin(), sweeps.end(), r.sweep) == sweeps.end()) sweeps.push_back(r.sweep);
    if (std::find(methods.begin(), methods.end(), r.method) == methods.end()) methods.push_back(r.method);
  }
  // One small CSV per sweep and method (rate, errors), one for the front.
  for (const auto& s : sweeps) {
    for (const std::string& m : methods) {
      std::ofstream f(dir + "/pareto_" + s + "_" + m + ".csv");
      f << "rate_hz,force_error_rel_rms,state_error_max,cutoff,budget,force_error_rel_rms_away_from_snaps,"
           "certified_rel_rms\n"
        << std::setprecision(6);
      for (const auto& r : rows)
        if (r.sweep == s && r.method == m && !r.default_settings)
          f << r.rate_hz.median << ',' << std::max(r.RelativeForceErrorRms(), 1e-16) << ','
            << std::max(r.stability.state_error_max, 1e-16) << ',' << r.cutoff << ',' << r.budget << ','
            << std::max(r.force_error_rel_rms_regular, 1e-16) << ',' << std::max(r.certified_rel_rms, 1e-16) << '\n';
    }
    {
      // The default settings (force tolerance 1e-4 of the force scale), one row per method.
      std::ofstream f(dir + "/pareto_" + s + "_default.csv");
      f << "rate_hz,force_error_rel_rms,state_error_max,certified_rel_rms,force_error_rel_rms_away_from_snaps\n"
        << std::setprecision(6);
      for (const auto& r : rows)
        if (r.sweep == s && r.default_settings)
          f << r.rate_hz.median << ',' << std::max(r.RelativeForceErrorRms(), 1e-16) << ','
            << std::max(r.stability.state_error_max, 1e-16) << ',' << std::max(r.certified_rel_rms, 1e-16) << ','
            << std::max(r.force_error_rel_rms_regular, 1e-16) << '\n';
    }
    std::vector<const AccuracyRow*> front;
    for (const auto& r : rows)
      if (r.sweep == s && r.pareto) front.push_back(&r);
    std::sort(front.begin(), front.end(), [](auto* a, auto* b) { return a->rate_hz.median < b->rate_hz.median; });
    std::ofstream f(dir + "/pareto_" + s + "_front.csv");
    f << "rate_hz,force_error_rel_rms\n" << std::setprecision(6);
    for (auto* r : front) f << r->rate_hz.median << ',' << std::max(r->RelativeForceErrorRms(), 1e-16) << '\n';
  }
  std::ostringstream gp;
  const int n = static_cast<int>(sweeps.size());
  gp << "set terminal pngcairo size 1900," << 380 * n + 60 << " font 'DejaVu Sans,10'\n"
     << "set output '" << png << "'\n"
     << "set termoption noenhanced\nset datafile separator ','\nset grid\nset key outside right top\n"
     << "set logscale x\nset logscale y\nset format x '%.0e'\nset format y '%.0e'\n"
     << "set multiplot layout " << n << ",3 title 'Speed against accuracy on the standard sweeps "
     << "(each point: one cutoff x budget, force tolerance 0; filled: true error against the reference, "
     << "newton-ls 1e-10 on finer steps; open: the certified estimate; black: the default settings, force "
     << "tolerance 1e-4)'\n";
  const char* titles[] = {": force error, all rows", ": force error away from snaps (> 2 rows)", ": state error"};
  const char* ylabels[] = {"rms force error / force scale (true, certified)", "rms |F - F_ref| / force scale",
                           "max |probe - probe_ref|"};
  const int columns[] = {2, 6, 3};
  for (const auto& s : sweeps) {
    for (int panel = 0; panel < 3; ++panel) {
      gp << "set title '" << s << titles[panel] << "'\n"
         << "set xlabel 'updates per second (median)'\n"
         << "set ylabel '" << ylabels[panel] << "'\n"
         << "plot ";
      bool first = true;
      for (const std::string& m : methods) {
        if (!first) gp << ", ";
        first = false;
        gp << "'" << dir << "/pareto_" << s << "_" << m << ".csv' every ::1 using 1:" << columns[panel]
           << " with points pt 7 ps 0.8 lc rgb '" << MethodColor(m) << "' title '" << m << "'";
      }
      if (panel == 0) {
        for (const std::string& m : methods)
          gp << ", '" << dir << "/pareto_" << s << "_" << m << ".csv' every ::1 using 1:7 with points pt 6 ps 0.8 lc rgb '"
             << MethodColor(m) << "' title '" << m << " certified'";
        gp << ", '" << dir << "/pareto_" << s << "_front.csv' every ::1 using 1:2 with linespoints pt 6 ps 1.2 dt 2 lc rgb '#444444' "
           << "title 'Pareto front (true error)'"
           << ", '" << dir << "/pareto_" << s << "_default.csv' every ::1 using 1:4 with points pt 8 ps 1.8 lc rgb '#000000' "
           << "title 'default settings, certified'";
      }
      // The default settings' true error, in every panel's own measure.
      const int default_columns[] = {2, 5, 3};
      gp << ", '" << dir << "/pareto_" << s << "_default.csv' every ::1 using 1:" << default_columns[panel]
         << " with points pt 9 ps 1.8 lc rgb '#000000' title 'default settings (force tolerance 1e-4)'";
      gp << "\n";
    }
  }
  gp << "unset multiplot\n";
  return gp.str();
}

}  // namespace snapthread
