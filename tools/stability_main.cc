// snapthread-stability: where methods fail. Runs the standard sweeps for each method
// and iteration budget, compares each with a tight reference trace, prints the table
// (chatter, snap placement, force error, cost), writes CSVs and a gnuplot chart of
// force traces (newton against higher-order, like the seed's Figs 2.5/2.7/2.10). Then
// the knot and rod scenes at several n: the rows each method leaves unconverged
// (resolution.csv, stability_resolution.h).
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include <CLI/CLI.hpp>

#include "progress.h"
#include "solvers/registry.h"
#include "stability.h"
#include "stability_resolution.h"
#include "tool_main.h"

namespace fs = std::filesystem;
using namespace snapthread;

namespace {

std::vector<int> ParseInts(const std::string& s, const char* what) {
  std::vector<int> v;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');) {
    if (item == "inf" || item == "0") {
      v.push_back(0);
      continue;
    }
    try {
      size_t used = 0;
      const int k = std::stoi(item, &used);
      if (used != item.size() || k < 0) throw std::invalid_argument(item);
      v.push_back(k);
    } catch (const std::exception&) {
      throw std::invalid_argument(std::string(what) + ": '" + item + "' is not an iteration budget (integer >= 1 or inf)");
    }
  }
  return v;
}

// Charted force traces of one sweep at one budget: reference and every method.
void WriteTraces(const fs::path& file, const StandardSweep& sw, const std::vector<SweepRow>& ref,
                 const std::vector<std::pair<std::string, std::vector<SweepRow>>>& traces) {
  std::ofstream out(file);
  const int c = sw.force_component;
  out << "step,control_distance,reference";
  for (const auto& [m, t] : traces) out << ',' << m;
  out << '\n';
  for (size_t i = 0; i < ref.size(); ++i) {
    out << i << ',' << i * sw.step << ',' << ref[i].force[c];
    for (const auto& [m, t] : traces) out << ',' << (i < t.size() ? t[i].force[c] : 0.0);
    out << '\n';
  }
}

// One row per charted sweep: the whole trace, and a zoom on the first reference snap.
bool Plot(const fs::path& dir, const std::vector<std::pair<std::string, int>>& sweeps, int budget) {
  const fs::path script = dir / "stability.gp";
  std::ofstream gp(script);
  const int n = static_cast<int>(sweeps.size());
  gp << "set terminal pngcairo size 1500," << 300 * n + 60 << " font 'DejaVu Sans,10'\n"
     << "set output '" << (dir / "stability.png").string() << "'\n"
     << "set termoption noenhanced\nset datafile separator ','\nset key top left\nset grid\n"
     << "set multiplot layout " << n << ",2 title 'Force on the grasp along standard sweeps, "
     << (budget == 0 ? std::string("unlimited") : std::to_string(budget))
     << " iterations per update (reference: newton-ls, cutoff 1e-10, 10x finer steps)'\n";
  for (const auto& [name, snap] : sweeps) {
    const std::string f = (dir / ("traces_" + name + ".csv")).string();
    // One curve per registered method (columns 4, 5, ... of the traces), the default
    // method (the seed's proposal) drawn thicker, then the reference.
    std::string curves;
    int column = 4;
    for (const std::string& m : SolverRegistry::Global().Names()) {
      curves += (curves.empty() ? "'" + f + "'" : std::string("''")) + " using 1:" + std::to_string(column++) +
                " with lines lw " + (m == SolverOptions{}.method ? "2" : "1") + " lc rgb '" + MethodColor(m) +
                "' title '" + m + "', ";
    }
    curves += "'' using 1:3 with lines lw 1 dt 2 lc rgb '#d62728' title 'reference'\n";
    gp << "set title '" << name << "'\nset xlabel 'update'\nset ylabel 'force component'\nset autoscale x\n"
       << "plot " << curves;
    gp << "set title '" << name << ": zoom on the first snap'\n";
    if (snap > 0) gp << "set xrange [" << std::max(0, snap - 40) << ":" << snap + 60 << "]\n";
    gp << "plot " << curves << "set autoscale x\n";
  }
  gp << "unset multiplot\n";
  gp.close();
  const std::string cmd = "gnuplot '" + script.string() + "'";
  return std::system(cmd.c_str()) == 0;
}

// Seed Fig 2.9: equilibria along a sweep through a snap at the haptic cutoff 1e-6 (a),
// their difference from 1e-10 solutions (b), and the 1e-8 - 1e-10 difference (c).
bool Figure29(const std::string& scenes_dir, const fs::path& dir, bool plot) {
  Scene scene = LoadScene(scenes_dir + "/curve2d_snap.yaml");
  SweepSpec spec;
  spec.from = Vec(2);
  spec.to = Vec(2);
  // From the bent-down branch at Y = -4 (the branch that snaps at Y = 3.41); the
  // chart shows 2.6 <= Y <= 4.
  spec.from << 9.0, -4.0;
  spec.to << 9.0, 4.0;
  spec.steps = 4000;
  std::map<double, std::vector<SweepRow>> runs;
  for (double cutoff : {1e-6, 1e-8, 1e-10}) {
    Scene sc = scene;
    sc.solver.cutoff = cutoff;
    sc.solver.max_iterations = 0;
    auto tracker = MakeTracker(sc);
    runs[cutoff] = RunSweep(tracker.get(), SweepControls(sc, spec));
  }
  std::ofstream out(dir / "fig29.csv");
  out << "step,u_y,probe_1e-6,dprobe_1e-6_1e-10,dprobe_1e-8_1e-10,dforce_1e-6_1e-10,dforce_1e-8_1e-10\n";
  const auto& a = runs[1e-6];
  const auto& b = runs[1e-8];
  const auto& c = runs[1e-10];
  for (size_t i = 0; i < a.size(); ++i)
    out << i << ',' << a[i].u[1] << ',' << a[i].probe << ',' << std::abs(a[i].probe - c[i].probe) << ','
        << std::abs(b[i].probe - c[i].probe) << ',' << (a[i].force - c[i].force).norm() << ','
        << (b[i].force - c[i].force).norm() << '\n';
  out.close();
  if (!plot) return true;
  std::ofstream gp(dir / "fig29.gp");
  const std::string f = (dir / "fig29.csv").string();
  gp << "set terminal pngcairo size 1000,900 font 'DejaVu Sans,10'\n"
     << "set output '" << (dir / "fig29.png").string() << "'\n"
     << "set datafile separator ','\nset grid\nset key top left\nset xlabel 'grasp Y (X = 9)'\n"
     << "set xrange [2.6:4.0]\n"
     << "set multiplot layout 3,1 title 'curve2d\\_snap through its snap at Y = 3.41 (after seed Fig 2.9)'\n"
     << "set ylabel 'y of node 5'\nplot '" << f << "' every ::1 using 2:3 with lines lw 2 title '(a) cutoff 1e-6'\n"
     << "set logscale y\nset format y '10^{%L}'\nset ylabel '|difference|'\n"
     << "plot '" << f << "' every ::1 using 2:($4+1e-17) with lines title '(b) node y: 1e-6 vs 1e-10', "
     << "'' every ::1 using 2:($6+1e-17) with lines title 'force: 1e-6 vs 1e-10'\n"
     << "plot '" << f << "' every ::1 using 2:($5+1e-17) with lines title '(c) node y: 1e-8 vs 1e-10', "
     << "'' every ::1 using 2:($7+1e-17) with lines title 'force: 1e-8 vs 1e-10'\n"
     << "unset multiplot\n";
  gp.close();
  return std::system(("gnuplot '" + (dir / "fig29.gp").string() + "'").c_str()) == 0;
}

// The resolution sweeps `names` selects ("all", "none", or a comma-separated list).
std::vector<ResolutionSweep> SelectResolution(const std::string& scenes_dir, const std::string& names) {
  std::vector<ResolutionSweep> all = ResolutionSweeps(scenes_dir);
  if (names == "all") return all;
  std::vector<ResolutionSweep> keep;
  if (names == "none") return keep;
  for (const std::string& name : SplitList(names)) {
    const auto it = std::find_if(all.begin(), all.end(), [&](const ResolutionSweep& r) { return r.name == name; });
    if (it == all.end()) throw std::invalid_argument("--resolution: no sweep named '" + name + "'");
    keep.push_back(*it);
  }
  return keep;
}

// The second table: each resolution sweep with each of `methods` (registered names).
void RunResolutionTable(const std::vector<ResolutionSweep>& sweeps, const std::vector<std::string>& methods,
                        const fs::path& out_dir) {
  if (sweeps.empty()) return;
  std::vector<ResolutionRow> table;
  const Progress progress("stability");
  const int total = static_cast<int>(sweeps.size() * methods.size());
  for (const ResolutionSweep& sw : sweeps) {
    for (const std::string& m : methods) {
      progress.Step(static_cast<int>(table.size()) + 1, total, sw.name + " with " + m);
      table.push_back(RunResolution(sw, m));
    }
  }
  std::cout << '\n';
  PrintResolutionTable(table, std::cout);
  std::ofstream csv(out_dir / "resolution.csv");
  WriteResolutionCsv(table, csv);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"snapthread-stability: chatter, snap placement and force error of each method on the standard sweeps"};
  std::string scenes_dir = SNAPTHREAD_SCENES_DIR, out_dir = "out/stability", budgets_text = "1,2,3,5,10,inf",
              only;
  int substeps = 10, plot_budget = 2;
  bool no_plot = false;
  app.add_option("--scenes", scenes_dir, "folder with the scene files");
  app.add_option("--out", out_dir, "output folder (CSV, traces, chart)");
  app.add_option("--budgets", budgets_text, "iteration budgets per update, comma-separated (inf = unlimited)");
  app.add_option("--sweeps", only, "only these sweeps (comma-separated names; none: only the --resolution ones)");
  app.add_option("--substeps", substeps, "reference: fine steps per row")->check(CLI::Range(1, 1000));
  app.add_option("--plot-budget", plot_budget, "budget whose traces are charted (0 = unlimited)");
  app.add_flag("--no-plot", no_plot, "skip the gnuplot chart");
  std::string resolution;
  app.add_option("--resolution", resolution,
                 "knot and rod scenes at several n (unconverged rows per method and n): all, none or names "
                 "(default: all, none with --sweeps naming standard sweeps)");
  std::string resolution_methods;
  app.add_option("--resolution-methods", resolution_methods,
                 "methods of the --resolution table, comma-separated (default: every registered one)");
  return RunTool("snapthread-stability", app, argc, argv, [&]() -> int {
    const std::vector<int> budgets = ParseInts(budgets_text, "--budgets");
    const bool standard_only = !only.empty() && only != "none";
    const std::vector<ResolutionSweep> resolution_sweeps =
        SelectResolution(scenes_dir, resolution.empty() ? (standard_only ? "none" : "all") : resolution);
    const std::vector<std::string> registered = SolverRegistry::Global().Names();
    const std::vector<std::string> methods = resolution_methods.empty() ? registered : SplitList(resolution_methods);
    for (const std::string& m : methods)
      if (std::find(registered.begin(), registered.end(), m) == registered.end())
        throw std::invalid_argument("--resolution-methods: no method named '" + m + "'");
    std::vector<StandardSweep> sweeps = StandardSweeps(scenes_dir);
    if (only == "none") {
      sweeps.clear();
    } else if (!only.empty()) {
      std::vector<StandardSweep> keep;
      std::stringstream ss(only);
      for (std::string name; std::getline(ss, name, ',');) {
        bool found = false;
        for (const auto& s : sweeps)
          if (s.name == name) {
            keep.push_back(s);
            found = true;
          }
        if (!found) throw std::invalid_argument("--sweeps: no sweep named '" + name + "'");
      }
      sweeps = keep;
    }
    fs::create_directories(out_dir);
    std::vector<StabilityRow> table;
    std::vector<std::pair<std::string, int>> charted;
    const std::vector<std::string> chart_names = {"zeeman_folds", "cusp_folds", "curve2d_snap", "thread3d_loop"};
    const Progress progress("stability");
    int done = 0;
    for (const auto& sw : sweeps) {
      progress.Step(++done, static_cast<int>(sweeps.size()),
                    sw.name + " (" + std::to_string(sw.controls.size()) + " updates): " + sw.description);
      const Scene scene = LoadScene(sw.scene_file);
      const auto ref = ReferenceTrace(scene, sw.controls, substeps);
      std::vector<std::pair<std::string, std::vector<SweepRow>>> chart;
      for (const std::string& m : SolverRegistry::Global().Names()) {
        for (int k : budgets) {
          Scene sc = scene;
          sc.solver.method = m;
          sc.solver.max_iterations = k;
          auto tracker = MakeTracker(sc);
          auto trace = RunSweep(tracker.get(), sw.controls);
          StabilityRow row = Compare(trace, ref);
          row.sweep = sw.name;
          row.method = m;
          row.budget = k;
          table.push_back(row);
          if (k == plot_budget) chart.emplace_back(m, std::move(trace));
        }
      }
      if (chart.size() == SolverRegistry::Global().Entries().size()) {
        WriteTraces(fs::path(out_dir) / ("traces_" + sw.name + ".csv"), sw, ref, chart);
        int first_snap = 0;
        for (const auto& r : ref)
          if (r.snapped && first_snap == 0) first_snap = r.step;
        if (std::find(chart_names.begin(), chart_names.end(), sw.name) != chart_names.end() || !only.empty())
          charted.push_back({sw.name, first_snap});
      }
    }
    PrintStabilityTable(table, std::cout);
    RunResolutionTable(resolution_sweeps, methods, out_dir);
    if (only.empty() && !Figure29(scenes_dir, out_dir, !no_plot)) {
      std::cerr << "stability: gnuplot failed for fig29\n";
      return 1;
    }
    std::ofstream csv(fs::path(out_dir) / "stability.csv");
    WriteStabilityCsv(table, csv);
    if (!no_plot && !charted.empty()) {
      if (!Plot(out_dir, charted, plot_budget)) {
        std::cerr << "stability: gnuplot failed (is gnuplot installed? deploy/setup.sh installs gnuplot-nox)\n";
        return 1;
      }
      std::cerr << "stability: chart " << (fs::path(out_dir) / "stability.png").string() << '\n';
    }
    return 0;
  });
}
