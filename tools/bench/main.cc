// snapthread-bench: speed against accuracy, scaling with n, service latency and the
// "model no more than a scene needs" advisor. See tools/bench/bench.h and docs/benchmarks.md.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <utility>

#include <CLI/CLI.hpp>

#include "app/command_line.h"
#include "bench.h"
#include "flood.h"
#include "path.h"
#include "progress.h"
#include "solvers/registry.h"
#include "tool_main.h"

namespace fs = std::filesystem;
using namespace snapthread;

namespace {

// Each benchmark's progress lines, on a terminal only (docs/cli.md).
const Progress& BenchProgress() {
  static const Progress progress("snapthread-bench");
  return progress;
}

std::vector<int> ParseBudgets(const std::string& s) {
  return ParseList<int>(s, "--budgets", "is not an iteration budget (integer >= 1, or inf)",
                        [](const std::string& item, int* k) {
                          if (item == "inf") return (*k = 0) == 0;
                          return ParseWhole(item, k) && *k >= 0;
                        });
}

std::vector<int> ParseCounts(const std::string& s, const char* what) {
  // At most the models' own limit on n (10^9 would allocate for minutes first).
  return ParseList<int>(s, what, "is not a segment count (integer in [2, 100000])",
                        [](const std::string& item, int* k) {
                          return ParseWhole(item, k) && *k >= 2 && *k <= 100000;
                        });
}

std::vector<double> ParseCutoffs(const std::string& s) {
  return ParseList<double>(s, "--cutoffs", "is not a positive number",
                           [](const std::string& item, double* c) { return ParseWhole(item, c) && *c > 0; });
}

std::vector<std::string> ParseMethods(const std::string& s) {
  std::vector<std::string> v;
  for (const auto& item : SplitList(s)) {
    if (SolverRegistry::Global().Find(item) == nullptr)
      throw std::invalid_argument("--methods: unknown method '" + item + "'");
    v.push_back(item);
  }
  return v;
}

std::string ExeDir() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string(".") : p.parent_path().string();
}

// The command line of snapthread-bench.
struct BenchFlags {
  std::string scenes_dir = SNAPTHREAD_SCENES_DIR, out_dir = "out/bench", only = "accuracy,scaling,service,path",
              bin_dir = ExeDir(), advise, methods_text, cutoffs_text, budgets_text, ns_text, backends_text,
              sweeps_text, ladder_text, service_scenes, path_ns_text;
  std::vector<std::string> sets;
  bool quick = false, no_plot = false, fixed_length = false, no_ceres = false, flood_rt = false;
  int repetitions = 0, reference_n = 0, path_steps = 0;
  double path_force_tolerance = -1.0;
  double service_duration = 0.0, target_force_error = 0.0, target_rate_hz = 0.0, flood_rate = 10000.0;
  std::string flood_scene = "curve2d_snap";
};

void AddChartFlags(CLI::App& cli, BenchFlags& f) {
  cli.add_flag("--quick", f.quick, "small grids, one repetition, short service run (for development)");
  cli.add_option("--only", f.only, "benchmarks to run: accuracy,scaling,service,path,rod,flood (comma-separated)");
  cli.add_option("--out", f.out_dir, "output folder (CSV, gnuplot scripts, PNG charts, summary.txt)");
  cli.add_option("--scenes", f.scenes_dir, "folder with the scene files");
  cli.add_option("--bin-dir", f.bin_dir, "folder with snapthread-server and snapthread-device (service)");
  cli.add_option("--repetitions", f.repetitions, "repetitions per measurement (default 3, quick 1)")
      ->check(CLI::Range(1, 100));
  cli.add_option("--methods", f.methods_text, "methods (default " + SolverRegistry::Global().NamesText(",", ",") + ")");
  cli.add_option("--cutoffs", f.cutoffs_text, "accuracy/advise: cutoffs (default 1e-4,1e-6,1e-8,1e-10)");
  cli.add_option("--budgets", f.budgets_text, "accuracy/advise: iteration budgets, inf = unlimited (default 1,2,3,5,10,inf)");
  cli.add_option("--sweeps", f.sweeps_text, "accuracy: standard sweeps (default zeeman_folds,cusp_folds,curve2d_snap,thread3d_loop)");
  cli.add_option("--ns", f.ns_text, "scaling: segment counts (default 5,10,20,50,100,200,500,1000,2000)");
  cli.add_flag("--fixed-length", f.fixed_length,
               "scaling: keep the thread's total length (finer segments) instead of n segments of length L");
  cli.add_option("--backends", f.backends_text, "scaling: linear solvers (default auto,banded,cholmod,dense)");
  cli.add_option("--path-ns", f.path_ns_text, "path: segment counts (default 10,100,1000)");
  cli.add_flag("--no-ceres", f.no_ceres, "path: skip the Ceres run (profiling the project's update alone)");
  cli.add_option("--path-force-tolerance", f.path_force_tolerance,
                 "path: solver.force_tolerance of the timed run (default: the default, 1e-4; 0 = the cutoff alone)")
      ->check(CLI::NonNegativeNumber)->check(app::FiniteNumber());
  cli.add_option("--path-steps", f.path_steps, "path: control steps per n (default 1000, quick 200)")
      ->check(CLI::Range(1, 1000000));
  cli.add_option("--service-scenes", f.service_scenes, "service: scene names (default curve2d_snap,thread3d_loop)");
  cli.add_option("--service-duration", f.service_duration, "service: seconds per run (default 10, quick 3)")
      ->check(CLI::Range(1.0, 600.0))->check(app::FiniteNumber());
  cli.add_option("--flood-rate", f.flood_rate, "flood: forged messages per second on each session channel (default 10000)")
      ->check(CLI::Range(1.0, 1e6));
  cli.add_flag("--flood-rt", f.flood_rt, "flood: run the device with SCHED_FIFO + mlockall (default --no-rt)");
  cli.add_option("--flood-scene", f.flood_scene, "flood: scene name (default curve2d_snap); seconds per run: --service-duration");
  cli.add_flag("--no-plot", f.no_plot, "skip the gnuplot charts");
}

void AddAdviseFlags(CLI::App& cli, BenchFlags& f) {
  cli.add_option("--advise", f.advise, "scene file: advise the smallest n and cheapest method/cutoff/budget instead");
  cli.add_option("--set", f.sets, "advise: scene override key=value (e.g. targets.rate_hz=20000), repeatable");
  cli.add_option("--target-force-error", f.target_force_error, "advise: force error target (overrides the scene's)")
      ->check(CLI::PositiveNumber)->check(app::FiniteNumber());
  cli.add_option("--target-rate-hz", f.target_rate_hz, "advise: rate target in updates/s (overrides the scene's)")
      ->check(CLI::PositiveNumber)->check(app::FiniteNumber());
  cli.add_option("--ladder", f.ladder_text, "advise: segment counts to try (default 5,8,10,15,20,30,50,80; reference 160)");
  cli.add_option("--reference-n", f.reference_n, "advise: segments of the reference model (default 2 max(n, ladder max))")
      ->check(CLI::Range(2, 100000));
}

// The accuracy chart and the advisor run the same grid of methods, cutoffs and budgets:
// --quick's smaller grid, then the command line's choices.
template <typename Options>
void ApplyGridFlags(const BenchFlags& f, int quick_substeps, Options* o) {
  if (f.quick) {
    o->cutoffs = {1e-6, 1e-10};
    o->budgets = {1, 3, 0};
    o->repetitions = 1;
    o->min_time_s = 0.01;
    o->substeps = quick_substeps;
  }
  if (!f.methods_text.empty()) o->methods = ParseMethods(f.methods_text);
  if (!f.cutoffs_text.empty()) o->cutoffs = ParseCutoffs(f.cutoffs_text);
  if (!f.budgets_text.empty()) o->budgets = ParseBudgets(f.budgets_text);
  if (f.repetitions > 0) o->repetitions = f.repetitions;
}

// --advise SCENE: exit 0 with the advice, 3 when nothing meets the targets.
int RunAdvise(const BenchFlags& f, const std::string& machine) {
  std::vector<SceneOverride> overrides;
  for (const auto& s : f.sets) overrides.push_back(ParseOverride(s));
  const Scene scene = LoadScene(f.advise, overrides);
  AdvisorOptions o;
  if (f.quick) o.n_ladder = {5, 8, 10, 15, 20};
  ApplyGridFlags(f, 2, &o);
  if (!f.ladder_text.empty()) o.n_ladder = ParseCounts(f.ladder_text, "--ladder");
  o.reference_n = f.reference_n;
  o.target_force_error = f.target_force_error;
  o.target_rate_hz = f.target_rate_hz;
  const Advice a = Advise(scene, o, BenchProgress().Stream());
  std::cout << "advise " << f.advise << " (" << machine << ")\n";
  PrintAdvice(a, std::cout);
  return a.found ? 0 : 3;
}

// Where the charts go: the summary, each chart's table, and whether gnuplot worked.
struct BenchOutput {
  std::string out_abs;  // --out, absolute (the gnuplot scripts name their PNGs by it)
  std::ofstream summary;
  bool plots_ok = true;

  // A chart's table on standard output and in summary.txt.
  void Table(const std::ostringstream& table) {
    std::cout << table.str();
    summary << table.str() << '\n';
  }
  // Writes a gnuplot script into --out and runs it (unless --no-plot).
  void Plot(const BenchFlags& f, const std::string& name, const std::string& script_text) {
    const std::string script = (fs::path(f.out_dir) / (name + ".gp")).string();
    std::ofstream(script) << script_text;
    if (!f.no_plot) plots_ok = RunGnuplot(script) && plots_ok;
  }
  std::string Png(const std::string& name) const { return out_abs + "/" + name + ".png"; }
};

void RunAccuracyChart(const BenchFlags& f, BenchOutput* out) {
  AccuracyOptions o;
  ApplyGridFlags(f, 3, &o);
  if (!f.sweeps_text.empty()) o.sweeps = SplitList(f.sweeps_text);
  const auto rows = RunAccuracyBench(f.scenes_dir, o, BenchProgress().Stream());
  std::ofstream csv(fs::path(f.out_dir) / "accuracy.csv");
  WriteAccuracyCsv(rows, csv);
  std::ostringstream table;
  table << "== speed against accuracy (median of " << o.repetitions
        << " runs; |dF|/Fs = rms force error / ForceScale; chatter = spurious force reversals; * = Pareto front)\n";
  PrintAccuracyTable(rows, false, table);
  out->Table(table);
  if (!f.no_plot) out->Plot(f, "bench_pareto", ParetoGnuplot(rows, out->out_abs, out->Png("bench_pareto")));
}

void RunRodChart(const BenchFlags& f, BenchOutput* out) {
  // The rod's targets: n = 10 >= 50 k and n = 100 >= 10 k updates/s.
  std::ostringstream table;
  table << "== rod: updates/s along rod_greenhill's path (median of " << std::max(f.repetitions, 3) << " runs)\n";
  RunRodSpeedBench(f.scenes_dir, {10, 100}, std::max(f.repetitions, 3), table);
  out->Table(table);
}

// Self-contact's cost against n, for the scaling chart's table and plot.
std::vector<ContactScalingRow> ContactScalingTable(const ScalingOptions& o, std::ostringstream& table) {
  const auto contact = RunContactScaling(o.ns, o.repetitions, o.min_sample_s);
  table << "== scaling: self-contact E + E_x + E_xx on a close helix (evaluations/s, median of " << o.repetitions
        << ")\n";
  for (const auto& r : contact) {
    table << "  n = " << r.n << ": " << r.rate_hz.median << " /s (" << r.active_pairs << " active of "
          << r.candidate_pairs << " candidate pairs)\n";
  }
  table << "  slope of the rate against n, n >= 100: " << FitContactScaling(contact).slope
        << " (-1: cost linear in n); n >= 20: " << FitContactScaling(contact, 20).slope << "\n";
  return contact;
}

void RunScalingChart(const BenchFlags& f, BenchOutput* out) {
  ScalingOptions o;
  if (f.quick) {
    o.ns = {5, 10, 100, 1000};
    o.repetitions = 1;
    o.min_sample_s = 0.05;
  }
  if (!f.ns_text.empty()) o.ns = ParseCounts(f.ns_text, "--ns");
  if (!f.methods_text.empty()) o.methods = ParseMethods(f.methods_text);
  if (!f.backends_text.empty()) o.backends = SplitList(f.backends_text);
  if (f.repetitions > 0) o.repetitions = f.repetitions;
  o.fixed_length = f.fixed_length;
  const auto rows = RunScalingBench(f.scenes_dir, o, BenchProgress().Stream());
  const auto fits = FitScaling(rows);
  std::ofstream csv(fs::path(f.out_dir) / "scaling.csv");
  WriteScalingCsv(rows, csv);
  std::ostringstream table;
  table << "== scaling: thread3d hand-speed update rate (median of " << o.repetitions << " repetitions; "
        << (f.fixed_length ? "fixed total length" : "n segments of length L") << ")\n";
  PrintScalingTable(rows, fits, table);
  PrintScalingTargets(rows, fits, table);
  const auto contact = ContactScalingTable(o, table);
  out->Table(table);
  if (!f.no_plot) {
    out->Plot(f, "bench_scaling",
              ScalingGnuplot(rows, fits, out->out_abs, out->Png("bench_scaling"), f.fixed_length, contact));
  }
}

void RunPathChart(const BenchFlags& f, BenchOutput* out) {
  PathOptions o;
  if (f.quick) {
    o.steps = 200;
    o.floor_samples = 51;
  }
  if (!f.path_ns_text.empty()) o.ns = ParseCounts(f.path_ns_text, "--path-ns");
  if (f.path_steps > 0) o.steps = f.path_steps;
  if (f.no_ceres) o.ceres = false;
  if (f.path_force_tolerance >= 0.0) o.force_tolerance = f.path_force_tolerance;
  const auto rows = RunPathBench(f.scenes_dir, o, BenchProgress().Stream());
  std::ostringstream table;
  table << "== path: thread3d (n - 0.5, 0.5, 0) -> (n - 0.5, 0.8, 0.2), " << o.steps << " steps, " << o.method
        << "/" << o.backend << ", cutoff " << o.cutoff << ", force tolerance "
        << (o.force_tolerance >= 0.0 ? o.force_tolerance : SolverOptions{}.force_tolerance)
        << "; medians over the updates; floor = plain banded LDL^T factor + solve of the last row's E_xx\n";
  PrintPathTable(rows, table);
  out->Table(table);
  // The path chart's script is written even with --no-plot.
  out->Plot(f, "bench_path", PathGnuplot(rows, out->out_abs, out->Png("bench_path")));
}

// The service and flood charts run server + device sessions alike: the binaries of
// --bin-dir, a work folder in --out, --quick's single 3 s run, --service-duration and
// --repetitions.
template <typename Options>
void ApplySessionFlags(const BenchFlags& f, const char* chart, Options* o) {
  o->bin_dir = f.bin_dir;
  o->scenes_dir = f.scenes_dir;
  o->work_dir = (fs::path(f.out_dir) / chart).string();
  if (f.quick) {
    o->duration_s = 3.0;
    o->repetitions = 1;
  }
  if (f.service_duration > 0) o->duration_s = f.service_duration;
  if (f.repetitions > 0) o->repetitions = f.repetitions;
}

template <typename Run>
void ReportFailedRuns(const std::vector<Run>& runs, const char* chart) {
  for (const auto& r : runs)
    if (!r.ok) std::cerr << "snapthread-bench: " << chart << " run failed: " << r.error << '\n';
}

void RunServiceChart(const BenchFlags& f, BenchOutput* out) {
  ServiceOptions o;
  ApplySessionFlags(f, "service", &o);
  if (f.quick) o.scenes = {"curve2d_snap"};
  if (!f.service_scenes.empty()) o.scenes = SplitList(f.service_scenes);
  const auto runs = RunServiceBench(o, BenchProgress().Stream());
  std::ofstream csv(fs::path(f.out_dir) / "service.csv");
  WriteServiceCsv(runs, csv);
  std::ostringstream table;
  table << "== service: server + device (virtual-hand, --no-rt, 1 kHz) on loopback, " << o.duration_s
        << " s per run\n";
  PrintServiceTable(runs, table);
  out->Table(table);
  ReportFailedRuns(runs, "service");
}

// A keyless flood of forged messages on every session channel during a genuine session
// (flood.h); not part of the default set (it loads the machine on purpose).
void RunFloodChart(const BenchFlags& f, BenchOutput* out) {
  FloodBenchOptions o;
  ApplySessionFlags(f, "flood", &o);
  o.scene = f.flood_scene;
  o.rate_per_channel_hz = f.flood_rate;
  o.realtime = f.flood_rt;
  const auto runs = RunFloodBench(o, BenchProgress().Stream());
  std::ofstream csv(fs::path(f.out_dir) / "flood.csv");
  WriteFloodCsv(runs, csv);
  std::ostringstream table;
  table << "== flood: " << o.scene << ", server + device (virtual-hand, " << (o.realtime ? "SCHED_FIFO" : "--no-rt")
        << ", 1 kHz) on loopback, " << o.duration_s << " s per run, " << o.rate_per_channel_hz
        << " forged msgs/s per channel\n";
  PrintFloodSummary(runs, table);
  out->Table(table);
  ReportFailedRuns(runs, "flood");
}

// The charts of --only, in a fixed order; returns the exit code (1: gnuplot failed).
int RunCharts(const BenchFlags& f, const std::string& machine) {
  const auto parts = SplitList(f.only);
  const char* const kCharts[] = {"accuracy", "scaling", "service", "path", "rod", "flood"};
  for (const auto& p : parts)
    if (std::find(std::begin(kCharts), std::end(kCharts), p) == std::end(kCharts))
      throw std::invalid_argument("--only: unknown benchmark '" + p + "' (accuracy, scaling, service, path, rod, flood)");
  auto want = [&](const char* p) { return std::find(parts.begin(), parts.end(), p) != parts.end(); };
  const auto t_start = std::chrono::steady_clock::now();
  fs::create_directories(f.out_dir);
  BenchOutput out;
  out.out_abs = fs::absolute(f.out_dir).string();
  out.summary.open(fs::path(f.out_dir) / "summary.txt");
  out.summary << "snapthread-bench " << (f.quick ? "--quick " : "") << "on " << machine << "\n\n";
  using Chart = void (*)(const BenchFlags&, BenchOutput*);
  const std::pair<const char*, Chart> kOrder[] = {{"accuracy", RunAccuracyChart}, {"rod", RunRodChart},
                                                   {"scaling", RunScalingChart},   {"path", RunPathChart},
                                                   {"service", RunServiceChart},   {"flood", RunFloodChart}};
  const int total_charts = static_cast<int>(std::count_if(std::begin(kOrder), std::end(kOrder),
                                                          [&](const auto& c) { return want(c.first); }));
  int done = 0;
  for (const auto& [name, run] : kOrder) {
    if (!want(name)) continue;
    BenchProgress().Step(++done, total_charts, name);
    run(f, &out);
  }
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  out.summary << "total " << total << " s\n";
  std::cerr << "snapthread-bench: done in " << total << " s; results in " << f.out_dir << '\n';
  if (!out.plots_ok) {
    std::cerr << "snapthread-bench: gnuplot failed (deploy/setup.sh installs gnuplot-nox)\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"snapthread-bench: speed against accuracy (Pareto), scaling with n, service latency; "
               "--advise SCENE picks the smallest model and cheapest solver meeting the scene's targets"};
  BenchFlags f;
  AddChartFlags(cli, f);
  AddAdviseFlags(cli, f);
  return RunTool("snapthread-bench", cli, argc, argv, [&]() -> int {
    const std::string machine = MachineDescription();
    std::cerr << "snapthread-bench: " << machine << (f.quick ? " (quick)" : "") << '\n';
    if (!f.advise.empty()) return RunAdvise(f, machine);
    return RunCharts(f, machine);
  });
}
