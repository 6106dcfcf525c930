#include "bench.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
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

extern char** environ;

namespace snapthread {
namespace {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

double Seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

std::string BudgetText(int budget) { return budget == 0 ? "inf" : std::to_string(budget); }

std::string Sci(double v, int digits = 2) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*e", digits, v);
  return buf;
}

// Relative rms force error of a trace against a reference of the same rows.
double RelativeRmsForceError(const std::vector<SweepRow>& trace, const std::vector<SweepRow>& ref, double scale) {
  const size_t n = std::min(trace.size(), ref.size());
  if (n == 0) return 0.0;
  double sum2 = 0.0;
  for (size_t i = 0; i < n; ++i) sum2 += (trace[i].force - ref[i].force).squaredNorm();
  return std::sqrt(sum2 / n) / scale;
}

double ForceScaleOf(const Scene& scene) { return MakeModel(scene.params)->ForceScale(); }

}  // namespace

// ---------------------------------------------------------------- statistics

Spread Summarize(std::vector<double> v) {
  Spread s;
  s.count = static_cast<int>(v.size());
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  s.min = v.front();
  s.max = v.back();
  s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  return s;
}

double PowerLawFit::At(double x) const { return std::pow(10.0, intercept + slope * std::log10(x)); }

PowerLawFit FitPowerLaw(const std::vector<double>& x, const std::vector<double>& y) {
  PowerLawFit f;
  std::vector<double> lx, ly;
  for (size_t i = 0; i < std::min(x.size(), y.size()); ++i)
    if (x[i] > 0 && y[i] > 0 && std::isfinite(x[i]) && std::isfinite(y[i])) {
      lx.push_back(std::log10(x[i]));
      ly.push_back(std::log10(y[i]));
    }
  f.points = static_cast<int>(lx.size());
  if (f.points < 2) return f;
  double mx = 0, my = 0;
  for (int i = 0; i < f.points; ++i) {
    mx += lx[i];
    my += ly[i];
  }
  mx /= f.points;
  my /= f.points;
  double sxx = 0, sxy = 0, syy = 0;
  for (int i = 0; i < f.points; ++i) {
    sxx += (lx[i] - mx) * (lx[i] - mx);
    sxy += (lx[i] - mx) * (ly[i] - my);
    syy += (ly[i] - my) * (ly[i] - my);
  }
  if (sxx <= 0) {  // all x equal: no slope to fit
    f.points = 1;
    return f;
  }
  f.slope = sxy / sxx;
  f.intercept = my - f.slope * mx;
  f.r2 = syy > 0 ? (sxy * sxy) / (sxx * syy) : 1.0;
  return f;
}

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

// ---------------------------------------------------------------- timed sweeps

TimedSweep TimeSweep(const Scene& scene, const std::vector<Vec>& controls, int repetitions, double min_time_s) {
  TimedSweep out;
  if (controls.size() < 2) throw std::invalid_argument("bench: a timed sweep needs two or more controls");
  std::vector<double> rates;
  const size_t rows = controls.size();
  double rep_seconds = 0.0;
  long rep_updates = 0;
  for (int pass = 0, rep = 0; rep < std::max(1, repetitions); ++pass) {
    auto tracker = MakeTracker(scene);
    const int m = tracker->model().NumControls();
    // Preallocated so the timed loop only copies a few numbers per update.
    Mat force(m, rows);
    std::vector<double> probe(rows), residual(rows), lambda(rows), solve_us(rows), energy(rows);
    std::vector<int> iters(rows), grads(rows), hess(rows);
    std::vector<char> snapped(rows, 0);
    std::vector<EquilibriumStatus> status(rows);
    std::vector<Termination> term(rows);
    auto keep = [&](size_t i, const TrackResult& r) {
      force.col(i) = r.force;
      probe[i] = r.probe;
      energy[i] = r.energy;
      residual[i] = r.summary.residual;
      lambda[i] = r.summary.lambda_min;
      solve_us[i] = r.summary.solve_us;
      iters[i] = r.summary.iterations;
      grads[i] = r.summary.gradient_evaluations;
      hess[i] = r.summary.hessian_evaluations;
      snapped[i] = i > 0 && r.snapped;
      status[i] = r.summary.status;
      term[i] = r.summary.termination;
    };
    keep(0, tracker->Reset(controls[0]));
    const auto t0 = Clock::now();
    for (size_t i = 1; i < rows; ++i) keep(i, tracker->Update(controls[i]));
    rep_seconds += Seconds(t0, Clock::now());
    rep_updates += static_cast<long>(rows - 1);
    const bool keep_rows = pass == 0;
    // A repetition runs the sweep again until it has lasted min_time_s (a short sweep
    // is below the clock's and the scheduler's resolution).
    if (rep_seconds >= min_time_s) {
      rates.push_back(rep_updates / std::max(rep_seconds, 1e-9));
      rep_seconds = 0.0;
      rep_updates = 0;
      ++rep;
    }
    if (keep_rows) {
      out.rows.resize(rows);
      for (size_t i = 0; i < rows; ++i) {
        SweepRow& r = out.rows[i];
        r.step = static_cast<int>(i);
        r.u = controls[i];
        r.force = force.col(i);
        r.probe = probe[i];
        r.energy = energy[i];
        r.residual = residual[i];
        r.lambda_min = lambda[i];
        r.solve_us = solve_us[i];
        r.iterations = iters[i];
        r.gradient_evaluations = grads[i];
        r.hessian_evaluations = hess[i];
        r.snapped = snapped[i];
        r.status = status[i];
        r.termination = term[i];
      }
    }
  }
  out.rate_hz = Summarize(rates);
  return out;
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
    for (Method m : o.methods) {
      const auto t_m = Clock::now();
      for (double cutoff : o.cutoffs)
        for (int budget : o.budgets) {
          Scene sc = scene;
          sc.solver.method = m;
          sc.solver.cutoff = cutoff;
          sc.solver.max_iterations = budget;
          const TimedSweep t = TimeSweep(sc, sw->controls, o.repetitions, o.min_time_s);
          AccuracyRow row;
          row.sweep = name;
          row.method = m;
          row.cutoff = cutoff;
          row.budget = budget;
          row.rate_hz = t.rate_hz;
          row.force_scale = scale;
          row.stability = Compare(t.rows, ref);
          row.force_error_rel_rms_regular = RegularRowsForceError(t.rows, ref, scale);
          row.stability.sweep = name;
          row.stability.method = m;
          row.stability.budget = budget;
          out.push_back(row);
        }
      if (progress)
        *progress << "bench accuracy: " << name << " " << ToString(m) << " (" << o.cutoffs.size() * o.budgets.size()
                  << " configurations x " << o.repetitions << ") in " << std::fixed << std::setprecision(1)
                  << Seconds(t_m, Clock::now()) << " s\n"
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
         "force_error_rel_rms_away_from_snaps\n";
  out << std::setprecision(6);
  for (const auto& r : rows) {
    const StabilityRow& s = r.stability;
    out << r.sweep << ',' << ToString(r.method) << ',' << r.cutoff << ',' << r.budget << ',' << r.rate_hz.median << ','
        << r.rate_hz.min << ',' << r.rate_hz.max << ',' << r.rate_hz.count << ',' << r.force_scale << ','
        << s.force_error_rms << ',' << s.force_error_max << ',' << r.RelativeForceErrorRms() << ','
        << s.state_error_max << ',' << s.spurious_reversals << ',' << s.reversals << ',' << s.reference_reversals
        << ',' << s.snaps << ',' << s.reference_snaps << ',' << s.snap_error_steps << ',' << s.mean_gradients << ','
        << s.mean_hessians << ',' << (r.pareto ? 1 : 0) << ',' << r.force_error_rel_rms_regular << '\n';
  }
}

void PrintAccuracyTable(const std::vector<AccuracyRow>& rows, bool pareto_only, std::ostream& out) {
  char buf[320];
  std::snprintf(buf, sizeof buf, "%-14s %-12s %7s %6s %11s %17s %10s %10s %10s %8s %9s %7s %6s\n", "sweep", "method",
                "cutoff", "budget", "rate(1/s)", "rate min..max", "|dF|/Fs", "off-snap", "|dx|max", "chatter",
                "snap_err", "grad/up", "front");
  out << buf;
  for (const auto& r : rows) {
    if (pareto_only && !r.pareto) continue;
    const StabilityRow& s = r.stability;
    const std::string snap = s.snap_error_steps < 0 ? "missed" : std::to_string(s.snap_error_steps);
    const std::string span = Sci(r.rate_hz.min, 1) + ".." + Sci(r.rate_hz.max, 1);
    std::snprintf(buf, sizeof buf, "%-14s %-12s %7.0e %6s %11.3e %17s %10.2e %10.2e %10.2e %8d %9s %7.2f %6s\n",
                  r.sweep.c_str(), ToString(r.method), r.cutoff, BudgetText(r.budget).c_str(), r.rate_hz.median,
                  span.c_str(), r.RelativeForceErrorRms(), r.force_error_rel_rms_regular, s.state_error_max,
                  s.spurious_reversals, snap.c_str(),
                  s.mean_gradients, r.pareto ? "*" : "");
    out << buf;
  }
}

// ---------------------------------------------------------------- scaling

Scene HandSpeedScene(const Scene& base, int n, Method method, const std::string& backend, double cutoff,
                     bool fixed_length) {
  if (base.params.model != "thread3d") throw std::invalid_argument("bench: the scaling scene must be a thread3d scene");
  Scene s = base;
  s.params.grip_direction = false;
  if (fixed_length) s = ResizeChain(s, n);
  s.name = base.name + "_n" + std::to_string(n);
  s.params.n = n;
  const double total = n * s.params.segment_length;
  s.grasp_start = Vec(3);
  s.grasp_start << 0.9 * total, 0.1 * total, 0.05 * total;
  s.path = {s.grasp_start};
  s.solver.method = method;
  s.solver.linear_solver = backend;
  s.solver.cutoff = cutoff;
  s.solver.max_iterations = 0;
  return s;
}

void HandSpeedControl(const Scene& scene, long i, Vec* u, double step) {
  if (u->size() != 3) u->resize(3);
  const double l = scene.params.segment_length;
  const double total = scene.params.n * l;
  const double a = 0.05 * total;  // amplitude of the back-and-forth in y
  const double t = std::fmod(i * (step > 0 ? step : 0.002 * l), 4 * a);
  const double dy = t < a ? t : (t < 3 * a ? 2 * a - t : t - 4 * a);
  (*u)[0] = scene.grasp_start[0];
  (*u)[1] = scene.grasp_start[1] + dy;
  (*u)[2] = scene.grasp_start[2];
}

ScalingRow TimeHandSpeed(const Scene& scene, const ScalingOptions& o) {
  ScalingRow row;
  row.method = scene.solver.method;
  row.backend = scene.solver.linear_solver;
  row.n = scene.params.n;
  auto tracker = MakeTracker(scene);
  Vec u = scene.grasp_start;
  tracker->Reset(u);
  long i = 0;
  // Warm-up: the secant predictor needs two previous states, caches get warm.
  for (int k = 0; k < 20; ++k) {
    HandSpeedControl(scene, ++i, &u, o.hand_step);
    tracker->Update(u);
  }
  std::vector<double> rates;
  long iterations = 0, timed = 0;
  int updates = 0;
  for (int rep = 0; rep < std::max(1, o.repetitions); ++rep) {
    int count = 0;
    const auto t0 = Clock::now();
    double s = 0.0;
    while (true) {
      HandSpeedControl(scene, ++i, &u, o.hand_step);
      const TrackResult& r = tracker->Update(u);
      ++count;
      iterations += r.summary.iterations;
      row.max_residual = std::max(row.max_residual, r.summary.residual);
      row.snaps += r.snapped ? 1 : 0;
      if (rep == 0) {
        // The first repetition sets the count: long enough for the clock and the noise.
        if (count >= o.min_updates || count % 16 == 0) {
          s = Seconds(t0, Clock::now());
          if (count >= o.min_updates && s >= o.min_sample_s) break;
        }
      } else if (count >= updates) {
        s = Seconds(t0, Clock::now());
        break;
      }
    }
    if (rep == 0) updates = count;
    timed += count;
    rates.push_back(count / std::max(s, 1e-9));
  }
  row.updates = updates;
  row.rate_hz = Summarize(rates);
  row.iterations_per_update = timed > 0 ? static_cast<double>(iterations) / timed : 0.0;
  return row;
}

std::vector<ScalingRow> RunScalingBench(const std::string& scenes_dir, const ScalingOptions& options,
                                        std::ostream* progress) {
  const Scene base = LoadScene(scenes_dir + "/thread3d_loop.yaml");
  ScalingOptions o = options;
  // Fixed length: the hand moves 0.002 L_base per update whatever the discretisation.
  if (o.fixed_length && o.hand_step <= 0) o.hand_step = 0.002 * base.params.segment_length;
  std::vector<ScalingRow> rows;
  std::vector<int> ns = o.ns;
  std::sort(ns.begin(), ns.end());
  // The last measured point per method/backend, for skipping sizes that would be too slow.
  std::map<std::pair<Method, std::string>, std::pair<int, double>> last;  // n, us per update
  // n outermost, methods and backends interleaved: a change in the machine's load hits
  // every method alike instead of biasing one against another.
  for (int n : ns)
    for (const std::string& backend : o.backends)
      for (Method m : o.methods) {
        const auto key = std::make_pair(m, backend);
        if (last.count(key)) {
          const auto [last_n, last_us] = last[key];
          // Dense LDL^T grows as n^3; the sparse ones about linearly (1.5 leaves room).
          const double p = backend == "dense" ? 3.0 : 1.5;
          const double predicted = last_us * std::pow(static_cast<double>(n) / last_n, p);
          if (predicted > o.max_update_us) {
            if (progress)
              *progress << "bench scaling: " << ToString(m) << "/" << backend << " n=" << n << " skipped (predicted "
                        << Sci(predicted) << " us per update > " << o.max_update_us << ")\n";
            continue;
          }
        }
        const auto t0 = Clock::now();
        ScalingRow r = TimeHandSpeed(HandSpeedScene(base, n, m, backend, o.cutoff, o.fixed_length), o);
        rows.push_back(r);
        last[key] = {n, 1e6 / std::max(r.rate_hz.median, 1e-9)};
        if (progress)
          *progress << "bench scaling: " << ToString(m) << "/" << backend << " n=" << n << ": "
                    << Sci(r.rate_hz.median) << " updates/s (" << r.updates << " x " << r.rate_hz.count << ", "
                    << std::fixed << std::setprecision(2) << r.iterations_per_update << " it/update, "
                    << std::setprecision(1) << Seconds(t0, Clock::now()) << " s)\n"
                    << std::defaultfloat << std::flush;
      }
  // Grouped per method and backend for the tables and charts.
  std::stable_sort(rows.begin(), rows.end(), [&](const ScalingRow& a, const ScalingRow& b) {
    auto mi = [&](Method m) { return std::find(o.methods.begin(), o.methods.end(), m) - o.methods.begin(); };
    auto bi = [&](const std::string& x) { return std::find(o.backends.begin(), o.backends.end(), x) - o.backends.begin(); };
    if (mi(a.method) != mi(b.method)) return mi(a.method) < mi(b.method);
    if (bi(a.backend) != bi(b.backend)) return bi(a.backend) < bi(b.backend);
    return a.n < b.n;
  });
  return rows;
}

std::vector<ScalingFit> FitScaling(const std::vector<ScalingRow>& rows) {
  std::vector<ScalingFit> fits;
  std::vector<std::pair<Method, std::string>> keys;
  for (const auto& r : rows)
    if (std::find(keys.begin(), keys.end(), std::make_pair(r.method, r.backend)) == keys.end())
      keys.push_back({r.method, r.backend});
  for (const auto& [m, b] : keys) {
    std::vector<double> x, y, xl, yl;
    for (const auto& r : rows)
      if (r.method == m && r.backend == b) {
        x.push_back(r.n);
        y.push_back(r.rate_hz.median);
        if (r.n >= 100) {
          xl.push_back(r.n);
          yl.push_back(r.rate_hz.median);
        }
      }
    fits.push_back({m, b, FitPowerLaw(x, y), FitPowerLaw(xl, yl)});
  }
  return fits;
}

void WriteScalingCsv(const std::vector<ScalingRow>& rows, std::ostream& out) {
  out << "method,backend,n,rate_hz_median,rate_hz_min,rate_hz_max,repetitions,updates_per_repetition,"
         "us_per_update_median,iterations_per_update,max_residual,snaps\n";
  out << std::setprecision(6);
  for (const auto& r : rows)
    out << ToString(r.method) << ',' << r.backend << ',' << r.n << ',' << r.rate_hz.median << ',' << r.rate_hz.min
        << ',' << r.rate_hz.max << ',' << r.rate_hz.count << ',' << r.updates << ','
        << 1e6 / std::max(r.rate_hz.median, 1e-12) << ',' << r.iterations_per_update << ',' << r.max_residual << ','
        << r.snaps << '\n';
}

void PrintScalingTable(const std::vector<ScalingRow>& rows, const std::vector<ScalingFit>& fits, std::ostream& out) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%-12s %-8s %6s %11s %21s %10s %8s %9s %5s\n", "method", "backend", "n", "rate(1/s)",
                "rate min..max", "us/update", "it/upd", "residual", "snaps");
  out << buf;
  for (const auto& r : rows) {
    const std::string span = Sci(r.rate_hz.min) + ".." + Sci(r.rate_hz.max);
    std::snprintf(buf, sizeof buf, "%-12s %-8s %6d %11.3e %21s %10.2f %8.2f %9.1e %5d\n", ToString(r.method),
                  r.backend.c_str(), r.n, r.rate_hz.median, span.c_str(), 1e6 / std::max(r.rate_hz.median, 1e-12),
                  r.iterations_per_update, r.max_residual, r.snaps);
    out << buf;
  }
  out << "fitted log-log slopes of rate against n (seed: -1.9):\n";
  for (const auto& f : fits) {
    std::snprintf(buf, sizeof buf, "  %-12s %-8s all n: %6.3f (%d points, r2 %.3f)   n >= 100: ", ToString(f.method),
                  f.backend.c_str(), f.all.slope, f.all.points, f.all.r2);
    out << buf;
    if (f.large.points >= 2) {
      std::snprintf(buf, sizeof buf, "%6.3f (%d points)\n", f.large.slope, f.large.points);
      out << buf;
    } else {
      out << "-\n";
    }
  }
}

void PrintScalingTargets(const std::vector<ScalingRow>& rows, const std::vector<ScalingFit>& fits, std::ostream& out) {
  auto rate = [&](Method m, const std::string& b, int n) {
    for (const auto& r : rows)
      if (r.method == m && r.backend == b && r.n == n) return r.rate_hz.median;
    return 0.0;
  };
  char buf[256];
  out << "issue-6 targets (higher-order, auto backend, cutoff 1e-6, hand-speed update):\n";
  for (const auto& [n, target] : std::vector<std::pair<int, double>>{{10, 1e5}, {100, 1e4}, {1000, 1e3}}) {
    const double r = rate(Method::kHigherOrder, "auto", n);
    if (r <= 0) {
      std::snprintf(buf, sizeof buf, "  n = %-5d >= %.0e /s: not measured\n", n, target);
    } else {
      std::snprintf(buf, sizeof buf, "  n = %-5d >= %.0e /s: measured %.3e /s -> %s\n", n, target, r,
                    r >= target ? "met" : "NOT met");
    }
    out << buf;
  }
  for (const auto& f : fits)
    if (f.method == Method::kHigherOrder && f.backend == "auto" && f.all.points >= 2) {
      std::snprintf(buf, sizeof buf, "  log-log slope >= -1.05: measured %.3f over all n (%.3f for n >= 100) -> %s\n",
                    f.all.slope, f.large.points >= 2 ? f.large.slope : f.all.slope,
                    f.all.slope >= -1.05 ? "met" : "NOT met");
      out << buf;
    }
  out << "  cost per update higher-order / newton (<= 1.3 targeted), per backend and n:\n";
  for (const std::string b : {"auto", "banded", "cholmod", "dense"}) {
    std::string line;
    double worst = 0.0;
    for (const auto& r : rows) {
      if (r.method != Method::kHigherOrder || r.backend != b) continue;
      const double rn = rate(Method::kNewton, b, r.n);
      if (rn <= 0 || r.rate_hz.median <= 0) continue;
      const double ratio = rn / r.rate_hz.median;  // us(higher-order) / us(newton)
      worst = std::max(worst, ratio);
      std::snprintf(buf, sizeof buf, " n=%d:%.2f", r.n, ratio);
      line += buf;
    }
    if (!line.empty()) {
      std::snprintf(buf, sizeof buf, "    %-8s worst %.2f ->%s |", b.c_str(), worst, worst <= 1.3 ? " met" : " NOT met");
      out << buf << line << '\n';
    }
  }
}

// ---------------------------------------------------------------- service

bool JsonNumber(const std::string& json, const std::string& key, double* value) {
  const std::string quoted = "\"" + key + "\"";
  size_t p = json.find(quoted);
  if (p == std::string::npos) return false;
  p = json.find(':', p + quoted.size());
  if (p == std::string::npos) return false;
  const char* begin = json.c_str() + p + 1;
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (end == begin || !std::isfinite(v)) return false;
  *value = v;
  return true;
}

namespace {

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Starts argv[0] with stdout and stderr into `log`; returns the pid or -1.
pid_t Spawn(const std::vector<std::string>& args, const std::string& log) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return rc == 0 ? pid : -1;
}

// Waits for pid up to `timeout_s`; returns its exit status, or -1 after killing it.
int WaitFor(pid_t pid, double timeout_s) {
  const auto t0 = Clock::now();
  while (true) {
    int status = 0;
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    if (r < 0) return -1;
    if (Seconds(t0, Clock::now()) > timeout_s) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace

ServiceRun RunServiceOnce(const ServiceOptions& o, const std::string& scene, int index) {
  ServiceRun run;
  run.scene = scene;
  const std::string server_bin = o.bin_dir + "/snapthread-server";
  const std::string device_bin = o.bin_dir + "/snapthread-device";
  for (const auto& b : {server_bin, device_bin})
    if (access(b.c_str(), X_OK) != 0) {
      run.error = b + " missing (build snapthread-server and snapthread-device)";
      return run;
    }
  const std::string scene_file = o.scenes_dir + "/" + scene + ".yaml";
  const std::string session = "BENCH_" + std::to_string(getpid()) + "_" + std::to_string(index);
  fs::create_directories(o.work_dir);
  const std::string base = o.work_dir + "/" + session;
  char duration[32], safety[32];
  std::snprintf(duration, sizeof duration, "%g", o.duration_s);
  std::snprintf(safety, sizeof safety, "%g", o.duration_s + 60.0);  // a safety net only
  const pid_t server =
      Spawn({server_bin, "--scene", scene_file, "--session", session, "--lcm-url", o.lcm_url, "--duration", safety,
             "--log-level", "info", "--summary", base + "_server.json"},
            base + "_server.log");
  if (server < 0) {
    run.error = "cannot start the server";
    return run;
  }
  // The server logs its session line once it has loaded the scene and subscribed.
  bool up = false;
  for (int k = 0; k < 300 && !up; ++k) {
    up = ReadFile(base + "_server.log").find("server: session") != std::string::npos;
    int status = 0;
    if (!up && waitpid(server, &status, WNOHANG) == server) {
      run.error = "the server exited at start (see " + base + "_server.log)";
      return run;
    }
    if (!up) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (!up) {
    kill(server, SIGTERM);
    WaitFor(server, 10);
    run.error = "the server did not start within 15 s (see " + base + "_server.log)";
    return run;
  }
  const pid_t device =
      Spawn({device_bin, "--backend", "virtual-hand", "--scene", scene_file, "--session", session, "--lcm-url",
             o.lcm_url, "--duration", duration, "--rate-hz", "1000", "--publish-divisor", "1", "--no-rt",
             "--summary", base + "_device.json"},
            base + "_device.log");
  int device_rc = device < 0 ? -1 : WaitFor(device, o.duration_s + 30.0);
  kill(server, SIGTERM);
  const int server_rc = WaitFor(server, 20.0);
  if (device_rc != 0 || server_rc != 0) {
    run.error = "device exit " + std::to_string(device_rc) + ", server exit " + std::to_string(server_rc) + " (logs " +
                base + "_*.log)";
    return run;
  }
  const std::string dev = ReadFile(base + "_device.json");
  const std::string srv = ReadFile(base + "_server.json");
  const bool ok = JsonNumber(dev, "round_trip_us_p50", &run.round_trip_us_p50) &&
                  JsonNumber(dev, "round_trip_us_p99", &run.round_trip_us_p99) &&
                  JsonNumber(dev, "lateness_us_p50", &run.lateness_us_p50) &&
                  JsonNumber(dev, "lateness_us_p99", &run.lateness_us_p99) &&
                  JsonNumber(dev, "tick_rate_hz", &run.tick_rate_hz);
  if (!ok) {
    run.error = "the device summary lacks round_trip_us_* / lateness_us_* (" + base + "_device.json)";
    return run;
  }
  JsonNumber(srv, "update_rate_hz", &run.server_update_rate_hz);
  JsonNumber(srv, "solve_us_p50", &run.server_solve_us_p50);
  JsonNumber(srv, "solve_us_p99", &run.server_solve_us_p99);
  run.ok = true;
  return run;
}

std::vector<ServiceRun> RunServiceBench(const ServiceOptions& o, std::ostream* progress) {
  std::vector<ServiceRun> runs;
  int index = 0;
  for (const auto& scene : o.scenes)
    for (int rep = 0; rep < std::max(1, o.repetitions); ++rep) {
      if (progress)
        *progress << "bench service: " << scene << " run " << rep + 1 << "/" << o.repetitions << " (" << o.duration_s
                  << " s)\n"
                  << std::flush;
      runs.push_back(RunServiceOnce(o, scene, index++));
      if (progress && !runs.back().ok) *progress << "bench service: failed: " << runs.back().error << '\n';
    }
  return runs;
}

void WriteServiceCsv(const std::vector<ServiceRun>& runs, std::ostream& out) {
  out << "scene,ok,round_trip_us_p50,round_trip_us_p99,lateness_us_p50,lateness_us_p99,tick_rate_hz,"
         "server_update_rate_hz,server_solve_us_p50,server_solve_us_p99,error\n";
  for (const auto& r : runs)
    out << r.scene << ',' << (r.ok ? 1 : 0) << ',' << r.round_trip_us_p50 << ',' << r.round_trip_us_p99 << ','
        << r.lateness_us_p50 << ',' << r.lateness_us_p99 << ',' << r.tick_rate_hz << ',' << r.server_update_rate_hz
        << ',' << r.server_solve_us_p50 << ',' << r.server_solve_us_p99 << ",\"" << r.error << "\"\n";
}

void PrintServiceTable(const std::vector<ServiceRun>& runs, std::ostream& out) {
  std::map<std::string, std::vector<const ServiceRun*>> by;
  std::vector<std::string> order;
  for (const auto& r : runs) {
    if (!by.count(r.scene)) order.push_back(r.scene);
    by[r.scene].push_back(&r);
  }
  char buf[256];
  std::snprintf(buf, sizeof buf, "%-14s %5s %22s %22s %22s %22s %18s %18s %18s\n", "scene", "runs",
                "round trip p50 us", "round trip p99 us", "lateness p50 us", "lateness p99 us", "tick Hz",
                "server updates/s", "server solve p99 us");
  out << buf << "  (median [min..max] over the runs)\n";
  for (const auto& s : order) {
    std::vector<double> a, b, c, d, e, f, g;
    int ok = 0;
    for (const ServiceRun* r : by[s]) {
      if (!r->ok) continue;
      ++ok;
      a.push_back(r->round_trip_us_p50);
      b.push_back(r->round_trip_us_p99);
      c.push_back(r->lateness_us_p50);
      d.push_back(r->lateness_us_p99);
      e.push_back(r->tick_rate_hz);
      f.push_back(r->server_update_rate_hz);
      g.push_back(r->server_solve_us_p99);
    }
    auto cell = [](const std::vector<double>& v) {
      const Spread sp = Summarize(v);
      char t[64];
      std::snprintf(t, sizeof t, "%.0f [%.0f..%.0f]", sp.median, sp.min, sp.max);
      return std::string(t);
    };
    std::snprintf(buf, sizeof buf, "%-14s %2d/%-2zu %22s %22s %22s %22s %18s %18s %18s\n", s.c_str(), ok,
                  by[s].size(), cell(a).c_str(), cell(b).c_str(), cell(c).c_str(), cell(d).c_str(), cell(e).c_str(),
                  cell(f).c_str(), cell(g).c_str());
    out << buf;
  }
}

// ---------------------------------------------------------------- advisor

bool IsChain(const Scene& s) { return s.params.model == "curve2d" || s.params.model == "thread3d"; }

Scene ResizeChain(const Scene& scene, int n) {
  if (!IsChain(scene)) return scene;
  Scene s = scene;
  const double l_old = scene.params.segment_length;
  const double l_new = scene.params.n * l_old / n;
  s.params.n = n;
  s.params.segment_length = l_new;
  // EI = beta l and EA ~ 2 gamma l are the continuum constants: keep beta l, gamma l.
  s.params.bending = scene.params.bending * l_old / l_new;
  s.params.stretching = scene.params.stretching * l_old / l_new;
  return s;
}

std::vector<Vec> HandSpeedPath(const Scene& scene) {
  constexpr double kStep = 0.002;                          // model units per update
  constexpr double kTurn = 0.5 * std::numbers::pi / 180;   // grip turn per update, rad
  const int pos = scene.params.model == "thread3d" ? 3 : 2;
  int steps = 1;
  for (size_t k = 1; k < scene.path.size(); ++k) {
    const Vec& a = scene.path[k - 1];
    const Vec& b = scene.path[k];
    double need = (b.head(pos) - a.head(pos)).norm() / kStep;
    if (scene.params.grip_direction) {
      const double c = std::clamp(a.tail(3).normalized().dot(b.tail(3).normalized()), -1.0, 1.0);
      need = std::max(need, std::acos(c) / kTurn);
    }
    steps = std::max(steps, static_cast<int>(std::ceil(need - 1e-2)));
  }
  return PathControls(scene, steps);
}

std::vector<SweepRow> TightTrace(const Scene& scene, const std::vector<Vec>& controls, int substeps,
                                 int max_iterations) {
  return ReferenceTrace(scene, controls, substeps, max_iterations);
}

int SelectCheapest(const std::vector<AdviceCandidate>& c, double te, double tr) {
  double fastest = -1.0;
  for (const auto& x : c)
    if (x.Acceptable(te, tr)) fastest = std::max(fastest, x.rate_hz);
  if (fastest < 0) return -1;
  // Rates within kRateTieFraction of the fastest are within the measurement noise of a
  // shared machine: among those the more accurate configuration wins.
  int best = -1;
  for (size_t i = 0; i < c.size(); ++i) {
    if (!c[i].Acceptable(te, tr) || c[i].rate_hz < (1.0 - kRateTieFraction) * fastest) continue;
    if (best < 0 || c[i].force_error < c[best].force_error ||
        (c[i].force_error == c[best].force_error && c[i].rate_hz > c[best].rate_hz))
      best = static_cast<int>(i);
  }
  return best;
}

Advice Advise(const Scene& scene, const AdvisorOptions& o, std::ostream* progress) {
  Advice a;
  a.target_force_error = o.target_force_error > 0 ? o.target_force_error : scene.target_force_error;
  a.target_rate_hz = o.target_rate_hz > 0 ? o.target_rate_hz : scene.target_rate_hz;
  if (!(a.target_force_error > 0) || !(a.target_rate_hz > 0))
    throw std::invalid_argument("advise: " + scene.file +
                                " states no targets: add targets: {force_error: <relative to the force scale>, "
                                "rate_hz: <updates per second>} or pass both targets on the command line");
  const std::vector<Vec> path = o.path.empty() ? HandSpeedPath(scene) : o.path;
  const bool chain = IsChain(scene);
  std::vector<int> ladder = o.n_ladder;
  std::sort(ladder.begin(), ladder.end());
  ladder.erase(std::unique(ladder.begin(), ladder.end()), ladder.end());
  if (!chain || ladder.empty()) ladder = {chain ? scene.params.n : 0};

  Scene ref_scene = scene;
  if (chain) {
    a.reference_n = o.reference_n > 0 ? o.reference_n : 2 * std::max(scene.params.n, ladder.back());
    ref_scene = ResizeChain(scene, a.reference_n);
    // A rung as fine as the reference would compare the reference with itself.
    std::erase_if(ladder, [&](int n) { return n >= a.reference_n; });
    if (ladder.empty()) throw std::invalid_argument("advise: every n of the ladder is >= the reference n");
  }
  const double scale = ForceScaleOf(ref_scene);
  const auto t_ref = Clock::now();
  const auto ref = TightTrace(ref_scene, path, std::max(1, o.substeps), o.tight_max_iterations);
  if (progress)
    *progress << "advise: " << scene.name << ": " << path.size() << " updates along grasp.path; reference"
              << (chain ? " n=" + std::to_string(a.reference_n) : std::string()) << " in " << std::fixed
              << std::setprecision(1) << Seconds(t_ref, Clock::now()) << " s\n"
              << std::defaultfloat << std::flush;

  for (int n : ladder) {
    const Scene sc = chain ? ResizeChain(scene, n) : scene;
    if (chain) {
      // The model's own error: the n-segment chain solved tightly, against the fine one.
      const double e = RelativeRmsForceError(TightTrace(sc, path, 1, o.tight_max_iterations), ref, scale);
      a.model_errors.push_back({n, e});
      if (progress) *progress << "advise: n=" << n << ": model error " << Sci(e) << '\n' << std::flush;
      if (e > a.target_force_error) continue;
    }
    std::vector<AdviceCandidate> here;
    for (Method m : o.methods)
      for (double cutoff : o.cutoffs)
        for (int budget : o.budgets) {
          Scene c = sc;
          c.solver.method = m;
          c.solver.cutoff = cutoff;
          c.solver.max_iterations = budget;
          const TimedSweep t = TimeSweep(c, path, o.repetitions, o.min_time_s);
          AdviceCandidate cand;
          cand.n = chain ? n : 0;
          cand.method = m;
          cand.cutoff = cutoff;
          cand.budget = budget;
          cand.rate_hz = t.rate_hz.median;
          cand.force_error = RelativeRmsForceError(t.rows, ref, scale);
          cand.spurious_reversals = Compare(t.rows, ref).spurious_reversals;
          here.push_back(cand);
        }
    a.candidates.insert(a.candidates.end(), here.begin(), here.end());
    const int best = SelectCheapest(here, a.target_force_error, a.target_rate_hz);
    if (progress)
      *progress << "advise: " << (chain ? "n=" + std::to_string(n) + ": " : std::string()) << here.size()
                << " configurations timed, " << (best >= 0 ? "one meets both targets" : "none meets both targets")
                << '\n'
                << std::flush;
    if (best >= 0) {
      a.found = true;
      a.choice = here[best];
      std::ostringstream msg;
      msg << "smallest model meeting the force target: "
          << (chain ? "n = " + std::to_string(n) : std::string("the scene's model")) << "; fastest configuration "
          << "meeting both targets: " << ToString(a.choice.method) << ", cutoff " << Sci(a.choice.cutoff, 0)
          << ", budget " << BudgetText(a.choice.budget) << " (" << Sci(a.choice.rate_hz) << " updates/s, force error "
          << Sci(a.choice.force_error) << ")";
      a.message = msg.str();
      return a;
    }
    double fastest = 0.0;
    for (const auto& c : here) fastest = std::max(fastest, c.rate_hz);
    if (fastest < a.target_rate_hz) {
      std::ostringstream msg;
      msg << "no configuration meets both targets: the fastest at "
          << (chain ? "n = " + std::to_string(n) : std::string("the scene's model")) << " gives " << Sci(fastest)
          << " updates/s < " << Sci(a.target_rate_hz) << (chain ? " and larger n are only slower" : "");
      a.message = msg.str();
      return a;
    }
    // Fast enough but every fast configuration is too inaccurate: a finer model may help.
  }
  std::ostringstream msg;
  msg << "no configuration meets both targets: ";
  if (chain) {
    const ModelErrorRow* best = nullptr;
    for (const auto& m : a.model_errors)
      if (!best || m.force_error < best->force_error) best = &m;
    msg << "along the ladder (up to n = " << ladder.back() << ") the smallest model error is "
        << Sci(best ? best->force_error : 0.0) << " (n = " << (best ? best->n : 0) << ")";
    if (!a.candidates.empty()) msg << "; where the model was fine enough, no fast configuration was accurate enough";
    msg << ", target " << Sci(a.target_force_error);
  } else {
    msg << "no fast enough configuration reaches a force error of " << Sci(a.target_force_error);
  }
  a.message = msg.str();
  return a;
}

void PrintAdvice(const Advice& a, std::ostream& out) {
  char buf[256];
  out << "targets: force error (rms |F - F_ref| / ForceScale) <= " << Sci(a.target_force_error)
      << ", rate >= " << Sci(a.target_rate_hz) << " updates/s\n";
  if (!a.model_errors.empty()) {
    out << "model error of each n (tight solve against the n=" << a.reference_n << " reference):\n";
    for (const auto& m : a.model_errors) {
      std::snprintf(buf, sizeof buf, "  n=%-5d %10.3e %s\n", m.n, m.force_error,
                    m.force_error <= a.target_force_error ? "meets" : "too coarse");
      out << buf;
    }
  }
  out << "configurations timed:\n";
  std::snprintf(buf, sizeof buf, "  %5s %-12s %7s %6s %11s %10s %8s  %s\n", "n", "method", "cutoff", "budget",
                "rate(1/s)", "|dF|/Fs", "chatter", "meets");
  out << buf;
  for (const auto& c : a.candidates) {
    const bool e = c.MeetsError(a.target_force_error) && c.spurious_reversals == 0,
               r = c.MeetsRate(a.target_rate_hz);
    const bool chosen = a.found && c.n == a.choice.n && c.method == a.choice.method && c.cutoff == a.choice.cutoff &&
                        c.budget == a.choice.budget;
    std::snprintf(buf, sizeof buf, "  %5d %-12s %7.0e %6s %11.3e %10.3e %8d  %s%s\n", c.n, ToString(c.method),
                  c.cutoff, BudgetText(c.budget).c_str(), c.rate_hz, c.force_error, c.spurious_reversals,
                  e && r ? "both" : (e ? "error only" : (r ? "rate only" : "neither")), chosen ? "   <== choice" : "");
    out << buf;
  }
  out << (a.found ? "advice: " : "advice: none: ") << a.message << '\n';
}

// ---------------------------------------------------------------- machine / charts

std::string MachineDescription() {
  std::string cpu = "unknown CPU";
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) {
      const size_t p = line.find(':');
      if (p != std::string::npos) cpu = line.substr(p + 2);
      break;
    }
  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  return "nproc " + std::to_string(std::thread::hardware_concurrency()) + ", CPU " + cpu + ", " + date;
}

bool RunGnuplot(const std::string& script) { return std::system(("gnuplot '" + script + "'").c_str()) == 0; }

namespace {
const char* MethodColor(Method m) {
  switch (m) {
    case Method::kNewton: return "#1f77b4";
    case Method::kNewtonLineSearch: return "#ff7f0e";
    case Method::kHigherOrder: return "#2ca02c";
  }
  return "#000000";
}
}  // namespace

std::string ParetoGnuplot(const std::vector<AccuracyRow>& rows, const std::string& dir, const std::string& png) {
  std::vector<std::string> sweeps;
  std::vector<Method> methods;
  for (const auto& r : rows) {
    if (std::find(sweeps.begin(), sweeps.end(), r.sweep) == sweeps.end()) sweeps.push_back(r.sweep);
    if (std::find(methods.begin(), methods.end(), r.method) == methods.end()) methods.push_back(r.method);
  }
  // One small CSV per sweep and method (rate, errors), one for the front.
  for (const auto& s : sweeps) {
    for (Method m : methods) {
      std::ofstream f(dir + "/pareto_" + s + "_" + ToString(m) + ".csv");
      f << "rate_hz,force_error_rel_rms,state_error_max,cutoff,budget,force_error_rel_rms_away_from_snaps\n"
        << std::setprecision(6);
      for (const auto& r : rows)
        if (r.sweep == s && r.method == m)
          f << r.rate_hz.median << ',' << std::max(r.RelativeForceErrorRms(), 1e-16) << ','
            << std::max(r.stability.state_error_max, 1e-16) << ',' << r.cutoff << ',' << r.budget << ','
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
     << "(each point: one cutoff x budget; reference newton-ls 1e-10, finer steps)'\n";
  const char* titles[] = {": force error, all rows", ": force error away from snaps (> 2 rows)", ": state error"};
  const char* ylabels[] = {"rms |F - F_ref| / force scale", "rms |F - F_ref| / force scale",
                           "max |probe - probe_ref|"};
  const int columns[] = {2, 6, 3};
  for (const auto& s : sweeps) {
    for (int panel = 0; panel < 3; ++panel) {
      gp << "set title '" << s << titles[panel] << "'\n"
         << "set xlabel 'updates per second (median)'\n"
         << "set ylabel '" << ylabels[panel] << "'\n"
         << "plot ";
      bool first = true;
      for (Method m : methods) {
        if (!first) gp << ", ";
        first = false;
        gp << "'" << dir << "/pareto_" << s << "_" << ToString(m) << ".csv' every ::1 using 1:" << columns[panel]
           << " with points pt 7 ps 0.8 lc rgb '" << MethodColor(m) << "' title '" << ToString(m) << "'";
      }
      if (panel == 0)
        gp << ", '" << dir << "/pareto_" << s << "_front.csv' every ::1 using 1:2 with linespoints pt 6 ps 1.2 dt 2 lc rgb '#444444' "
           << "title 'Pareto front'";
      gp << "\n";
    }
  }
  gp << "unset multiplot\n";
  return gp.str();
}

std::string ScalingGnuplot(const std::vector<ScalingRow>& rows, const std::vector<ScalingFit>& fits,
                           const std::string& dir, const std::string& png, bool fixed_length) {
  std::vector<Method> methods;
  for (const auto& r : rows)
    if (std::find(methods.begin(), methods.end(), r.method) == methods.end()) methods.push_back(r.method);
  const std::map<std::string, std::string> colors = {
      {"auto", "#2ca02c"}, {"banded", "#1f77b4"}, {"cholmod", "#ff7f0e"}, {"dense", "#9467bd"}};
  for (const auto& f : fits) {
    std::ofstream out(dir + "/scaling_" + ToString(f.method) + "_" + f.backend + ".csv");
    out << "n,rate_hz_median,rate_hz_min,rate_hz_max\n" << std::setprecision(6);
    for (const auto& r : rows)
      if (r.method == f.method && r.backend == f.backend)
        out << r.n << ',' << r.rate_hz.median << ',' << r.rate_hz.min << ',' << r.rate_hz.max << '\n';
  }
  std::ostringstream gp;
  const int n = static_cast<int>(methods.size());
  gp << "set terminal pngcairo size " << 560 * n << ",560 font 'DejaVu Sans,10'\n"
     << "set output '" << png << "'\n"
     << "set termoption noenhanced\nset datafile separator ','\nset grid\nset key bottom left\n"
     << "set logscale x\nset logscale y\nset format y '%.0e'\n"
     << "set xlabel 'n (segments)'\nset ylabel 'hand-speed updates per second'\n"
     << "set multiplot layout 1," << n << " title 'thread3d equilibrium-update rate against n (cutoff 1e-6, "
     << (fixed_length ? "fixed total length 10 L, 0.002 L per update in y" : "n segments of length L, 0.002 L per update in y")
     << "); error bars: min..max over repetitions'\n";
  for (Method m : methods) {
    gp << "set title '" << ToString(m) << "'\nplot ";
    bool first = true;
    double anchor_n = 0, anchor_rate = 0;
    for (const auto& f : fits) {
      if (f.method != m) continue;
      if (!first) gp << ", ";
      first = false;
      const std::string file = dir + "/scaling_" + ToString(m) + "_" + f.backend + ".csv";
      const std::string c = colors.count(f.backend) ? colors.at(f.backend) : "#000000";
      char slope[64];
      std::snprintf(slope, sizeof slope, "%.2f", f.all.slope);
      gp << "'" << file << "' every ::1 using 1:2:3:4 with yerrorlines pt 7 ps 0.6 lc rgb '" << c << "' title '"
         << f.backend << " (slope " << slope << ")'";
      if (f.backend == "auto")
        for (const auto& r : rows)
          if (r.method == m && r.backend == "auto" && (anchor_n == 0 || r.n < anchor_n)) {
            anchor_n = r.n;
            anchor_rate = r.rate_hz.median;
          }
    }
    if (anchor_n > 0) {
      // The seed's measured cost, n^-1.9, through the first auto point.
      gp << ", " << anchor_rate << "*(x/" << anchor_n << ")**(-1.9) with lines dt 2 lc rgb '#d62728' title "
         << "'seed n^-1.9'";
      gp << ", " << anchor_rate << "*(x/" << anchor_n << ")**(-1.0) with lines dt 3 lc rgb '#7f7f7f' title "
         << "'n^-1 (linear cost)'";
    }
    gp << "\n";
  }
  gp << "unset multiplot\n";
  return gp.str();
}

}  // namespace snapthread
