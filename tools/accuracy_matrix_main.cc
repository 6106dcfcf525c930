// snapthread-accuracy: the accuracy matrix (docs/accuracy.md, "Accuracy targets"). For
// each model, family, n and path kind, the default settings against a round-off-polished
// reference: every row's force error, the statuses against the reference's branch, and
// how well the certified force error bounds each row's own error. Prints a Markdown
// table (to standard output) and writes a CSV; exits 1 when a cell misses a target.
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "accuracy_matrix.h"
#include "tool_main.h"

using namespace snapthread;

int main(int argc, char** argv) {
  CLI::App app{"snapthread-accuracy: force error and certified estimate, thread3d and rod, at several n"};
  std::string models = "thread3d,rod", families = "unit,fixed-L", paths = "hand,large", ns_text = "10,100,1000";
  std::string csv_path = "accuracy_matrix.csv", rows_path;
  double cutoff = 0.0;
  app.add_option("--models", models, "models (thread3d,rod)");
  app.add_option("--families", families, "families: unit (n unit segments), fixed-L (a fixed length, continuum stiffnesses)");
  app.add_option("--paths", paths, "paths: hand (100 steps), large (20 steps)");
  app.add_option("--n", ns_text, "segment counts");
  app.add_option("--csv", csv_path, "the CSV to write");
  app.add_option("--rows-csv", rows_path, "also every row of every cell into this CSV");
  app.add_option("--cutoff", cutoff, "an explicit cutoff (force tolerance 0), instead of the defaults")
      ->check(CLI::PositiveNumber);
  return RunTool("snapthread-accuracy", app, argc, argv, [&]() {
    const std::vector<int> ns = ParseList<int>(ns_text, "--n", "is not a segment count >= 10",
                                               [](const std::string& s, int* v) { return ParseWhole(s, v) && *v >= 10; });
    std::vector<AccuracyCell> cells;
    for (const std::string& m : SplitList(models)) {
      if (m != "thread3d" && m != "rod") throw std::invalid_argument("--models: '" + m + "' is not thread3d or rod");
      for (const std::string& f : SplitList(families)) {
        if (f != "unit" && f != "fixed-L") throw std::invalid_argument("--families: '" + f + "' is not unit or fixed-L");
        for (int n : ns)
          for (const std::string& p : SplitList(paths)) {
            if (p != "hand" && p != "large") throw std::invalid_argument("--paths: '" + p + "' is not hand or large");
            cells.push_back({m, f == "unit" ? AccuracyFamily::kUnitSegments : AccuracyFamily::kFixedLength, n,
                             p == "hand" ? AccuracyPath::kHandSpeed : AccuracyPath::kLargeSteps});
          }
      }
    }
    SolverOptions options;
    if (cutoff > 0.0) {
      options.cutoff = cutoff;
      options.force_tolerance = 0.0;
    }
    std::vector<AccuracyCellResult> results;
    const AccuracyTargets targets;
    bool all_met = true;
    for (const AccuracyCell& c : cells) {
      results.push_back(RunAccuracyCell(c, options));
      const AccuracyCellResult& r = results.back();
      all_met = all_met && r.MeetsErrorTargets(targets) && r.MeetsEstimateTargets(targets);
      std::cerr << "snapthread-accuracy: " << c.model << ' ' << ToString(c.family) << " n=" << c.n << ' '
                << ToString(c.path) << ": error max " << r.error_max << ", covered " << r.covered << '/' << r.rows
                << ", " << r.seconds << " s\n";
    }
    PrintAccuracyMatrix(results, targets, std::cout);
    std::ofstream csv(csv_path);
    WriteAccuracyMatrixCsv(results, csv);
    if (!rows_path.empty()) {
      std::ofstream rows(rows_path);
      WriteAccuracyRowsCsv(results, rows);
    }
    return all_met ? 0 : 1;
  });
}
