// snapthread-sweep: offline quasi-static sweep of a scene along a straight control path,
// one CSV row per step.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>

#include <CLI/CLI.hpp>

#include "models/registry.h"
#include "scene/scene_schema.h"
#include "solvers/registry.h"
#include "progress.h"
#include "sweep.h"
#include "tool_main.h"

int main(int argc, char** argv) {
  using namespace snapthread;
  CLI::App app{"snapthread-sweep: quasi-static sweep of a scene's grasp from --from to --to"};
  std::string scene_file, from, to, method, out_file;
  int steps = 100, max_iterations = -1;
  double cutoff = 0.0, time_budget_us = 0.0;
  bool back = false;
  std::vector<std::string> sets;
  app.add_option("--scene", scene_file, "scene YAML file")->required();
  bool use_path = false;
  auto* from_opt = app.add_option("--from", from, "start grasp X,Y[,Z] (model units)");
  auto* to_opt = app.add_option("--to", to, "end grasp X,Y[,Z] (model units)");
  auto* path_opt = app.add_flag("--path", use_path, "follow the scene's grasp.path instead (N steps per leg)");
  from_opt->needs(to_opt);
  to_opt->needs(from_opt);
  path_opt->excludes(from_opt)->excludes(to_opt);
  app.add_option("--steps", steps, "number of equal steps N (rows 0..N), or per leg with --path");
  app.add_flag("--back", back, "continue N more steps back to --from (2N+1 rows)");
  app.add_option("--method", method, SolverRegistry::Global().NamesText(" | ", " | ") + " (default: the scene's)");
  app.add_option("--cutoff", cutoff,
                 "stop when |E_x| < cutoff, and on nothing else (default: the scene's cutoff and its "
                 "solver.force_tolerance of the force scale, docs/accuracy.md)");
  double force_tolerance = -1.0;
  app.add_option("--force-tolerance", force_tolerance,
                 "stop when the certified force error is within this fraction of the model's force scale "
                 "(default: the scene's solver.force_tolerance, 1e-4; 0 = the cutoff alone)");
  app.add_option("--max-iterations", max_iterations, "iteration budget per step, 0 = unlimited");
  app.add_option("--time-budget-us", time_budget_us,
                 "wall-clock budget per step in microseconds, 0 = none (a snap may then spread over steps: "
                 "termination 'snapping')");
  app.add_option("--set", sets, "override a scene key, e.g. --set params.n=20 (repeatable)");
  app.add_option("--out", out_file, "CSV output file (default: standard output)");
  std::string shape_file;
  app.add_option("--shape-out,--shapes-out", shape_file,
                 "also write every row's node positions (step,node,x,y,z) to this CSV");
  bool exact = false;
  app.add_flag("--exact", exact,
               "write every number but solve_us with 17 significant digits (each double exactly: "
               "tools/same_bits/check.sh compares runs bit for bit)");
  // docs/scenes.md, printed from the loader's schema (no scene needed: it ends the parse).
  app.add_flag_callback(
      "--print-scene-schema",
      [] {
        WriteSceneSchemaMarkdown(std::cout);
        throw CLI::Success();
      },
      "print every scene key (meaning, unit, default, range) as Markdown: docs/scenes.md");
  // The models a scene may name, with their parameters (--set params.<name>=...).
  app.footer("Models (scene key `model:`):\n" + ModelHelp());
  const auto run = [&]() -> int {
    std::vector<SceneOverride> overrides;
    for (const auto& s : sets) overrides.push_back(ParseOverride(s));
    Scene scene = LoadScene(scene_file, overrides);
    if (!method.empty()) {
      if (SolverRegistry::Global().Find(method) == nullptr)
        throw std::invalid_argument("--method: expected " + SolverRegistry::Global().NamesText(", ", " or ") +
                                    ", got '" + method + "'");
      scene.solver.method = method;
    }
    if (app.count("--cutoff")) {
      if (!(cutoff > 0.0)) throw std::invalid_argument("--cutoff: expected a number > 0");
      scene.solver.cutoff = cutoff;
      // An explicit cutoff keeps its meaning: |E_x| < cutoff and nothing else.
      scene.solver.force_tolerance = 0.0;
    }
    if (app.count("--force-tolerance")) {
      if (!(force_tolerance >= 0.0) || !std::isfinite(force_tolerance))
        throw std::invalid_argument("--force-tolerance: expected a finite number >= 0");
      scene.solver.force_tolerance = force_tolerance;
    }
    if (app.count("--max-iterations")) {
      if (max_iterations < 0) throw std::invalid_argument("--max-iterations: expected an integer >= 0");
      scene.solver.max_iterations = max_iterations;
    }
    if (app.count("--time-budget-us")) {
      if (!(time_budget_us >= 0.0) || !std::isfinite(time_budget_us))
        throw std::invalid_argument("--time-budget-us: expected a finite number >= 0");
      scene.solver.max_time_us = time_budget_us;
    }
    if (steps < 1) throw std::invalid_argument("--steps: expected an integer >= 1");
    std::vector<Vec> controls;
    if (use_path) {
      if (back) throw std::invalid_argument("--back: not with --path (write the way back into the path)");
      controls = PathControls(scene, steps);
    } else {
      if (from.empty()) throw std::invalid_argument("--from/--to or --path: one of them is required");
      const int dim = scene.grasp_layout.spatial_dimension;
      SweepSpec spec;
      spec.from = ParsePoint(from, dim, "--from");
      spec.to = ParsePoint(to, dim, "--to");
      spec.steps = steps;
      spec.back = back;
      controls = SweepControls(scene, spec);
    }
    auto tracker = MakeTracker(scene);
    // A line a second on a terminal (docs/cli.md, "Progress"); nothing in a pipe or a test.
    const Progress progress("sweep");
    auto last = std::chrono::steady_clock::now();
    const auto rows = RunSweep(tracker.get(), controls, [&](size_t done, size_t total) {
      const auto now = std::chrono::steady_clock::now();
      if (!progress.active() || now - last < std::chrono::seconds(1)) return;
      last = now;
      progress.Step(static_cast<int>(done), static_cast<int>(total), "rows");
    });
    if (!shape_file.empty()) {
      std::ofstream shapes(shape_file);
      if (!shapes) throw std::runtime_error("--shape-out: cannot write '" + shape_file + "'");
      WriteShapeCsv(rows, tracker->model(), shapes, exact ? 17 : 9);
    }
    const int grasps = std::max<int>(1, static_cast<int>(scene.grasps.size()));
    const int digits = exact ? 17 : 12;
    if (out_file.empty()) {
      WriteSweepCsv(rows, scene.solver.method, std::cout, scene.grasp_layout, grasps, digits);
    } else {
      std::ofstream out(out_file);
      if (!out) throw std::runtime_error("--out: cannot write '" + out_file + "'");
      WriteSweepCsv(rows, scene.solver.method, out, scene.grasp_layout, grasps, digits);
    }
    return 0;
  };
  ToolExitCodes codes;
  codes.scene_error_is_bad_input = true;
  return RunTool("snapthread-sweep", app, argc, argv, run, codes);
}
