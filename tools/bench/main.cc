// snapthread-bench: speed against accuracy, scaling with n, service latency and the
// "model no more than a scene needs" advisor. See tools/bench/bench.h and docs/benchmarks.md.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <utility>

#include <CLI/CLI.hpp>

#include "bench.h"
#include "flood.h"
#include "path.h"
#include "solvers/registry.h"
#include "tool_main.h"

namespace fs = std::filesystem;
using namespace snapthread;

namespace {

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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"snapthread-bench: speed against accuracy (Pareto), scaling with n, service latency; "
               "--advise SCENE picks the smallest model and cheapest solver meeting the scene's targets"};
  std::string scenes_dir = SNAPTHREAD_SCENES_DIR, out_dir = "out/bench", only = "accuracy,scaling,service,path",
              bin_dir = ExeDir(), advise, methods_text, cutoffs_text, budgets_text, ns_text, backends_text,
              sweeps_text, ladder_text, service_scenes, path_ns_text;
  std::vector<std::string> sets;
  bool quick = false, no_plot = false, fixed_length = false, no_ceres = false, flood_rt = false;
  int repetitions = 0, reference_n = 0, path_steps = 0;
  double service_duration = 0.0, target_force_error = 0.0, target_rate_hz = 0.0, flood_rate = 10000.0;
  std::string flood_scene = "curve2d_snap";
  app.add_flag("--quick", quick, "small grids, one repetition, short service run (for development)");
  app.add_option("--only", only, "benchmarks to run: accuracy,scaling,service,path,rod,flood (comma-separated)");
  app.add_option("--out", out_dir, "output folder (CSV, gnuplot scripts, PNG charts, summary.txt)");
  app.add_option("--scenes", scenes_dir, "folder with the scene files");
  app.add_option("--bin-dir", bin_dir, "folder with snapthread-server and snapthread-device (service)");
  app.add_option("--repetitions", repetitions, "repetitions per measurement (default 3, quick 1)")
      ->check(CLI::Range(1, 100));
  app.add_option("--methods", methods_text, "methods (default " + SolverRegistry::Global().NamesText(",", ",") + ")");
  app.add_option("--cutoffs", cutoffs_text, "accuracy/advise: cutoffs (default 1e-4,1e-6,1e-8,1e-10)");
  app.add_option("--budgets", budgets_text, "accuracy/advise: iteration budgets, inf = unlimited (default 1,2,3,5,10,inf)");
  app.add_option("--sweeps", sweeps_text, "accuracy: standard sweeps (default zeeman_folds,cusp_folds,curve2d_snap,thread3d_loop)");
  app.add_option("--ns", ns_text, "scaling: segment counts (default 5,10,20,50,100,200,500,1000,2000)");
  app.add_flag("--fixed-length", fixed_length,
               "scaling: keep the thread's total length (finer segments) instead of n segments of length L");
  app.add_option("--backends", backends_text, "scaling: linear solvers (default auto,banded,cholmod,dense)");
  app.add_option("--path-ns", path_ns_text, "path: segment counts (default 10,100,1000)");
  app.add_flag("--no-ceres", no_ceres, "path: skip the Ceres run (profiling the project's update alone)");
  app.add_option("--path-steps", path_steps, "path: control steps per n (default 1000, quick 200)")
      ->check(CLI::Range(1, 1000000));
  app.add_option("--service-scenes", service_scenes, "service: scene names (default curve2d_snap,thread3d_loop)");
  app.add_option("--service-duration", service_duration, "service: seconds per run (default 10, quick 3)")
      ->check(CLI::Range(1.0, 600.0));
  app.add_option("--flood-rate", flood_rate, "flood: forged messages per second on each session channel (default 10000)")
      ->check(CLI::Range(1.0, 1e6));
  app.add_flag("--flood-rt", flood_rt, "flood: run the device with SCHED_FIFO + mlockall (default --no-rt)");
  app.add_option("--flood-scene", flood_scene, "flood: scene name (default curve2d_snap); seconds per run: --service-duration");
  app.add_flag("--no-plot", no_plot, "skip the gnuplot charts");
  app.add_option("--advise", advise, "scene file: advise the smallest n and cheapest method/cutoff/budget instead");
  app.add_option("--set", sets, "advise: scene override key=value (e.g. targets.rate_hz=20000), repeatable");
  app.add_option("--target-force-error", target_force_error, "advise: force error target (overrides the scene's)")
      ->check(CLI::PositiveNumber);
  app.add_option("--target-rate-hz", target_rate_hz, "advise: rate target in updates/s (overrides the scene's)")
      ->check(CLI::PositiveNumber);
  app.add_option("--ladder", ladder_text, "advise: segment counts to try (default 5,8,10,15,20,30,50,80; reference 160)");
  app.add_option("--reference-n", reference_n, "advise: segments of the reference model (default 2 max(n, ladder max))")
      ->check(CLI::Range(2, 100000));
  return RunTool("snapthread-bench", app, argc, argv, [&]() -> int {
    // CLI11's range checks let "nan" through (it fails no comparison).
    for (const auto& [flag, value] : {std::pair<const char*, double>{"--service-duration", service_duration},
                                      {"--target-force-error", target_force_error},
                                      {"--target-rate-hz", target_rate_hz}}) {
      if (!std::isfinite(value)) throw std::invalid_argument(std::string(flag) + ": expected a finite number");
    }
    const std::string machine = MachineDescription();
    std::cerr << "snapthread-bench: " << machine << (quick ? " (quick)" : "") << '\n';
    const auto t_start = std::chrono::steady_clock::now();
    if (!advise.empty()) {
      std::vector<SceneOverride> overrides;
      for (const auto& s : sets) overrides.push_back(ParseOverride(s));
      const Scene scene = LoadScene(advise, overrides);
      AdvisorOptions o;
      if (quick) {
        o.n_ladder = {5, 8, 10, 15, 20};
        o.cutoffs = {1e-6, 1e-10};
        o.budgets = {1, 3, 0};
        o.repetitions = 1;
        o.min_time_s = 0.01;
        o.substeps = 2;
      }
      if (!ladder_text.empty()) o.n_ladder = ParseCounts(ladder_text, "--ladder");
      if (!methods_text.empty()) o.methods = ParseMethods(methods_text);
      if (!cutoffs_text.empty()) o.cutoffs = ParseCutoffs(cutoffs_text);
      if (!budgets_text.empty()) o.budgets = ParseBudgets(budgets_text);
      if (repetitions > 0) o.repetitions = repetitions;
      o.reference_n = reference_n;
      o.target_force_error = target_force_error;
      o.target_rate_hz = target_rate_hz;
      const Advice a = Advise(scene, o, &std::cerr);
      std::cout << "advise " << advise << " (" << machine << ")\n";
      PrintAdvice(a, std::cout);
      return a.found ? 0 : 3;
    }

    const auto parts = SplitList(only);
    auto want = [&](const char* p) { return std::find(parts.begin(), parts.end(), p) != parts.end(); };
    for (const auto& p : parts)
      if (p != "accuracy" && p != "scaling" && p != "service" && p != "path" && p != "rod" && p != "flood")
        throw std::invalid_argument("--only: unknown benchmark '" + p +
                                    "' (accuracy, scaling, service, path, rod, flood)");
    fs::create_directories(out_dir);
    const std::string out_abs = fs::absolute(out_dir).string();
    std::ofstream summary(fs::path(out_dir) / "summary.txt");
    summary << "snapthread-bench " << (quick ? "--quick " : "") << "on " << machine << "\n\n";
    bool plots_ok = true;

    if (want("accuracy")) {
      AccuracyOptions o;
      if (quick) {
        o.cutoffs = {1e-6, 1e-10};
        o.budgets = {1, 3, 0};
        o.repetitions = 1;
        o.min_time_s = 0.01;
        o.substeps = 3;
      }
      if (!sweeps_text.empty()) o.sweeps = SplitList(sweeps_text);
      if (!methods_text.empty()) o.methods = ParseMethods(methods_text);
      if (!cutoffs_text.empty()) o.cutoffs = ParseCutoffs(cutoffs_text);
      if (!budgets_text.empty()) o.budgets = ParseBudgets(budgets_text);
      if (repetitions > 0) o.repetitions = repetitions;
      const auto rows = RunAccuracyBench(scenes_dir, o, &std::cerr);
      std::ofstream csv(fs::path(out_dir) / "accuracy.csv");
      WriteAccuracyCsv(rows, csv);
      std::ostringstream table;
      table << "== speed against accuracy (median of " << o.repetitions
            << " runs; |dF|/Fs = rms force error / ForceScale; chatter = spurious force reversals; * = Pareto front)\n";
      PrintAccuracyTable(rows, false, table);
      std::cout << table.str();
      summary << table.str() << '\n';
      if (!no_plot) {
        const std::string script = (fs::path(out_dir) / "bench_pareto.gp").string();
        std::ofstream(script) << ParetoGnuplot(rows, out_abs, out_abs + "/bench_pareto.png");
        plots_ok = RunGnuplot(script) && plots_ok;
      }
    }

    if (want("rod")) {
      // Issue 14's targets: n = 10 >= 50 k and n = 100 >= 10 k updates/s.
      std::ostringstream table;
      table << "== rod: updates/s along rod_greenhill's path (median of " << std::max(repetitions, 3) << " runs)\n";
      RunRodSpeedBench(scenes_dir, {10, 100}, std::max(repetitions, 3), table);
      std::cout << table.str();
      summary << table.str() << '\n';
    }

    if (want("scaling")) {
      ScalingOptions o;
      if (quick) {
        o.ns = {5, 10, 100, 1000};
        o.repetitions = 1;
        o.min_sample_s = 0.05;
      }
      if (!ns_text.empty()) o.ns = ParseCounts(ns_text, "--ns");
      if (!methods_text.empty()) o.methods = ParseMethods(methods_text);
      if (!backends_text.empty()) o.backends = SplitList(backends_text);
      if (repetitions > 0) o.repetitions = repetitions;
      o.fixed_length = fixed_length;
      const auto rows = RunScalingBench(scenes_dir, o, &std::cerr);
      const auto fits = FitScaling(rows);
      std::ofstream csv(fs::path(out_dir) / "scaling.csv");
      WriteScalingCsv(rows, csv);
      std::ostringstream table;
      table << "== scaling: thread3d hand-speed update rate (median of " << o.repetitions << " repetitions; "
            << (fixed_length ? "fixed total length" : "n segments of length L") << ")\n";
      PrintScalingTable(rows, fits, table);
      PrintScalingTargets(rows, fits, table);
      // Issue 15 item 8: self-contact's cost against n, on the same chart.
      const auto contact = RunContactScaling(o.ns, o.repetitions, o.min_sample_s);
      table << "== scaling: self-contact E + E_x + E_xx on a close helix (evaluations/s, median of "
            << o.repetitions << ")\n";
      for (const auto& r : contact) {
        table << "  n = " << r.n << ": " << r.rate_hz.median << " /s (" << r.active_pairs << " active of "
              << r.candidate_pairs << " candidate pairs)\n";
      }
      table << "  slope of the rate against n, n >= 100: " << FitContactScaling(contact).slope
            << " (-1: cost linear in n); n >= 20: " << FitContactScaling(contact, 20).slope << "\n";
      std::cout << table.str();
      summary << table.str() << '\n';
      if (!no_plot) {
        const std::string script = (fs::path(out_dir) / "bench_scaling.gp").string();
        std::ofstream(script) << ScalingGnuplot(rows, fits, out_abs, out_abs + "/bench_scaling.png", fixed_length,
                                                  contact);
        plots_ok = RunGnuplot(script) && plots_ok;
      }
    }

    if (want("path")) {
      PathOptions o;
      if (quick) {
        o.steps = 200;
        o.floor_samples = 51;
      }
      if (!path_ns_text.empty()) o.ns = ParseCounts(path_ns_text, "--path-ns");
      if (path_steps > 0) o.steps = path_steps;
      if (no_ceres) o.ceres = false;
      const auto rows = RunPathBench(scenes_dir, o, &std::cerr);
      std::ostringstream table;
      table << "== path: thread3d (n - 0.5, 0.5, 0) -> (n - 0.5, 0.8, 0.2), " << o.steps << " steps, " << o.method
            << "/" << o.backend << ", cutoff " << o.cutoff
            << "; medians over the updates; floor = plain banded LDL^T factor + solve of the last row's E_xx\n";
      PrintPathTable(rows, table);
      std::cout << table.str();
      summary << table.str() << '\n';
      const std::string script = (fs::path(out_dir) / "bench_path.gp").string();
      std::ofstream(script) << PathGnuplot(rows, out_abs, out_abs + "/bench_path.png");
      if (!no_plot) plots_ok = RunGnuplot(script) && plots_ok;
    }

    if (want("service")) {
      ServiceOptions o;
      o.bin_dir = bin_dir;
      o.scenes_dir = scenes_dir;
      o.work_dir = (fs::path(out_dir) / "service").string();
      if (quick) {
        o.scenes = {"curve2d_snap"};
        o.duration_s = 3.0;
        o.repetitions = 1;
      }
      if (!service_scenes.empty()) o.scenes = SplitList(service_scenes);
      if (service_duration > 0) o.duration_s = service_duration;
      if (repetitions > 0) o.repetitions = repetitions;
      const auto runs = RunServiceBench(o, &std::cerr);
      std::ofstream csv(fs::path(out_dir) / "service.csv");
      WriteServiceCsv(runs, csv);
      std::ostringstream table;
      table << "== service: server + device (virtual-hand, --no-rt, 1 kHz) on loopback, " << o.duration_s
            << " s per run\n";
      PrintServiceTable(runs, table);
      std::cout << table.str();
      summary << table.str() << '\n';
      for (const auto& r : runs)
        if (!r.ok) std::cerr << "snapthread-bench: service run failed: " << r.error << '\n';
    }
    if (want("flood")) {
      // A keyless flood of forged messages on every session channel during a genuine
      // session (flood.h); not part of the default set (it loads the machine on purpose).
      FloodBenchOptions o;
      o.bin_dir = bin_dir;
      o.scenes_dir = scenes_dir;
      o.scene = flood_scene;
      o.rate_per_channel_hz = flood_rate;
      o.realtime = flood_rt;
      o.work_dir = (fs::path(out_dir) / "flood").string();
      if (quick) {
        o.duration_s = 3.0;
        o.repetitions = 1;
      }
      if (service_duration > 0) o.duration_s = service_duration;
      if (repetitions > 0) o.repetitions = repetitions;
      const auto runs = RunFloodBench(o, &std::cerr);
      std::ofstream csv(fs::path(out_dir) / "flood.csv");
      WriteFloodCsv(runs, csv);
      std::ostringstream table;
      table << "== flood: " << o.scene << ", server + device (virtual-hand, " << (o.realtime ? "SCHED_FIFO" : "--no-rt")
            << ", 1 kHz) on loopback, "
            << o.duration_s << " s per run, " << o.rate_per_channel_hz << " forged msgs/s per channel\n";
      PrintFloodSummary(runs, table);
      std::cout << table.str();
      summary << table.str() << '\n';
      for (const auto& r : runs)
        if (!r.ok) std::cerr << "snapthread-bench: flood run failed: " << r.error << '\n';
    }
    const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    summary << "total " << total << " s\n";
    std::cerr << "snapthread-bench: done in " << total << " s; results in " << out_dir << '\n';
    if (!plots_ok) {
      std::cerr << "snapthread-bench: gnuplot failed (deploy/setup.sh installs gnuplot-nox)\n";
      return 1;
    }
    return 0;
  });
}
