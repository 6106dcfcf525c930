// Scaling chart: thread3d hand-speed update rate against n, power-law fits.
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

// ---------------------------------------------------------------- scaling

Scene HandSpeedScene(const Scene& base, int n, const std::string& method, const std::string& backend, double cutoff,
                     bool fixed_length) {
  if (!IsChain(base.params) || base.grasp_layout.spatial_dimension != 3)
    throw std::invalid_argument("bench: the scaling scene must be a chain in three dimensions (" + base.file + ")");
  Scene s = base;
  // The timing runs without a grip direction: the plain (X, Y, Z) grasp.
  if (FindModel(s.params.model)->FindParam("grip_direction") != nullptr) s.params.Set("grip_direction", false);
  s.grasp_layout = GraspLayoutOf(s.params);
  if (fixed_length) s = ResizeChain(s, n);
  s.name = base.name + "_n" + std::to_string(n);
  s.params = SetChainSegments(s.params, n);
  const double total = n * ChainSegmentLength(s.params);
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
  const double l = ChainSegmentLength(scene.params);
  const double total = ChainSegments(scene.params) * l;
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
  row.n = ChainSegments(scene.params);
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
  if (o.fixed_length && o.hand_step <= 0) o.hand_step = 0.002 * ChainSegmentLength(base.params);
  std::vector<ScalingRow> rows;
  std::vector<int> ns = o.ns;
  std::sort(ns.begin(), ns.end());
  // The last measured point per method/backend, for skipping sizes that would be too slow.
  std::map<std::pair<std::string, std::string>, std::pair<int, double>> last;  // n, us per update
  // n outermost, methods and backends interleaved: a change in the machine's load hits
  // every method alike instead of biasing one against another.
  for (int n : ns)
    for (const std::string& backend : o.backends)
      for (const std::string& m : o.methods) {
        const auto key = std::make_pair(m, backend);
        if (last.count(key)) {
          const auto [last_n, last_us] = last[key];
          // Dense LDL^T grows as n^3; the sparse ones about linearly (1.5 leaves room).
          const double p = backend == "dense" ? 3.0 : 1.5;
          const double predicted = last_us * std::pow(static_cast<double>(n) / last_n, p);
          if (predicted > o.max_update_us) {
            if (progress)
              *progress << "bench scaling: " << m << "/" << backend << " n=" << n << " skipped (predicted "
                        << Sci(predicted) << " us per update > " << o.max_update_us << ")\n";
            continue;
          }
        }
        const auto t0 = Clock::now();
        ScalingRow r = TimeHandSpeed(HandSpeedScene(base, n, m, backend, o.cutoff, o.fixed_length), o);
        rows.push_back(r);
        last[key] = {n, 1e6 / std::max(r.rate_hz.median, 1e-9)};
        if (progress)
          *progress << "bench scaling: " << m << "/" << backend << " n=" << n << ": "
                    << Sci(r.rate_hz.median) << " updates/s (" << r.updates << " x " << r.rate_hz.count << ", "
                    << std::fixed << std::setprecision(2) << r.iterations_per_update << " it/update, "
                    << std::setprecision(1) << Seconds(t0, Clock::now()) << " s)\n"
                    << std::defaultfloat << std::flush;
      }
  // Grouped per method and backend for the tables and charts.
  std::stable_sort(rows.begin(), rows.end(), [&](const ScalingRow& a, const ScalingRow& b) {
    auto mi = [&](const std::string& m) { return std::find(o.methods.begin(), o.methods.end(), m) - o.methods.begin(); };
    auto bi = [&](const std::string& x) { return std::find(o.backends.begin(), o.backends.end(), x) - o.backends.begin(); };
    if (mi(a.method) != mi(b.method)) return mi(a.method) < mi(b.method);
    if (bi(a.backend) != bi(b.backend)) return bi(a.backend) < bi(b.backend);
    return a.n < b.n;
  });
  return rows;
}

std::vector<ScalingFit> FitScaling(const std::vector<ScalingRow>& rows) {
  std::vector<ScalingFit> fits;
  std::vector<std::pair<std::string, std::string>> keys;
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
    out << r.method << ',' << r.backend << ',' << r.n << ',' << r.rate_hz.median << ',' << r.rate_hz.min
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
    std::snprintf(buf, sizeof buf, "%-12s %-8s %6d %11.3e %21s %10.2f %8.2f %9.1e %5d\n", r.method.c_str(),
                  r.backend.c_str(), r.n, r.rate_hz.median, span.c_str(), 1e6 / std::max(r.rate_hz.median, 1e-12),
                  r.iterations_per_update, r.max_residual, r.snaps);
    out << buf;
  }
  out << "fitted log-log slopes of rate against n (seed: -1.9):\n";
  for (const auto& f : fits) {
    std::snprintf(buf, sizeof buf, "  %-12s %-8s all n: %6.3f (%d points, r2 %.3f)   n >= 100: ", f.method.c_str(),
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
  auto rate = [&](const std::string& m, const std::string& b, int n) {
    for (const auto& r : rows)
      if (r.method == m && r.backend == b && r.n == n) return r.rate_hz.median;
    return 0.0;
  };
  char buf[256];
  out << "targets (higher-order, auto backend, cutoff 1e-6, hand-speed update):\n";
  for (const auto& [n, target] : std::vector<std::pair<int, double>>{{10, 1e5}, {100, 1e4}, {1000, 1e3}}) {
    const double r = rate("higher-order", "auto", n);
    if (r <= 0) {
      std::snprintf(buf, sizeof buf, "  n = %-5d >= %.0e /s: not measured\n", n, target);
    } else {
      std::snprintf(buf, sizeof buf, "  n = %-5d >= %.0e /s: measured %.3e /s -> %s\n", n, target, r,
                    r >= target ? "met" : "NOT met");
    }
    out << buf;
  }
  for (const auto& f : fits)
    if (f.method == "higher-order" && f.backend == "auto" && f.all.points >= 2) {
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
      if (r.method != "higher-order" || r.backend != b) continue;
      const double rn = rate("newton", b, r.n);
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

std::string ScalingGnuplot(const std::vector<ScalingRow>& rows, const std::vector<ScalingFit>& fits,
                           const std::string& dir, const std::string& png, bool fixed_length,
                           const std::vector<ContactScalingRow>& contact) {
  char contact_slope[64] = "";
  if (!contact.empty()) {
    std::ofstream out(dir + "/contact_scaling.csv");
    out << std::setprecision(6);
    WriteContactScalingCsv(contact, out);
    std::snprintf(contact_slope, sizeof contact_slope, "%.2f", FitContactScaling(contact).slope);
  }
  std::vector<std::string> methods;
  for (const auto& r : rows)
    if (std::find(methods.begin(), methods.end(), r.method) == methods.end()) methods.push_back(r.method);
  const std::map<std::string, std::string> colors = {
      {"auto", "#2ca02c"}, {"banded", "#1f77b4"}, {"cholmod", "#ff7f0e"}, {"dense", "#9467bd"}};
  for (const auto& f : fits) {
    std::ofstream out(dir + "/scaling_" + f.method + "_" + f.backend + ".csv");
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
  for (const std::string& m : methods) {
    gp << "set title '" << m << "'\nplot ";
    bool first = true;
    double anchor_n = 0, anchor_rate = 0;
    for (const auto& f : fits) {
      if (f.method != m) continue;
      if (!first) gp << ", ";
      first = false;
      const std::string file = dir + "/scaling_" + m + "_" + f.backend + ".csv";
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
    if (!contact.empty()) {
      gp << (first ? "" : ", ") << "'" << dir << "/contact_scaling.csv' every ::1 using 1:2:3:4 with yerrorlines "
         << "pt 5 ps 0.6 lc rgb '#000000' title 'contact E,E_x,E_xx /s (slope " << contact_slope << ", n>=100)'";
      first = false;
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
