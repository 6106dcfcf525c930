// Shared by the bench's charts: statistics, timed sweeps, machine description, gnuplot.
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

std::string Sci(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*e", digits, v);
  return buf;
}

double RelativeRmsForceError(const std::vector<SweepRow>& trace, const std::vector<SweepRow>& ref, double scale) {
  const size_t n = std::min(trace.size(), ref.size());
  if (n == 0) return 0.0;
  double sum2 = 0.0;
  for (size_t i = 0; i < n; ++i) sum2 += (trace[i].force - ref[i].force).squaredNorm();
  return std::sqrt(sum2 / n) / scale;
}

double ForceScaleOf(const Scene& scene) { return MakeModel(scene.params)->ForceScale(); }

Scene WithSolver(const Scene& scene, const std::string& method, double cutoff, int budget) {
  Scene s = scene;
  s.solver.method = method;
  s.solver.cutoff = cutoff;
  s.solver.max_iterations = budget;
  return s;
}

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
    std::vector<double> probe(rows), residual(rows), lambda(rows), solve_us(rows), energy(rows), certified(rows);
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
      certified[i] = r.summary.force_error;
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
        r.force_error = certified[i];
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

}  // namespace snapthread
