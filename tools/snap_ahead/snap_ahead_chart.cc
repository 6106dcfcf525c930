// snapthread-snap-ahead-chart: the snap position error (in servo ticks of travel) against
// the server's update rate, with and without snap-ahead, for the given scenes (issue 17,
// docs/snap-ahead.md). One CSV row per scene, rate, mode and snap; the sessions run on a
// fake clock (snap_session.h), so the numbers do not depend on the machine's load.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "scene/scene.h"
#include "snap_session.h"

namespace {

using snapthread::snap_ahead::ForceJumps;
using snapthread::snap_ahead::RunSession;
using snapthread::snap_ahead::SessionOptions;
using snapthread::snap_ahead::TrueFolds;

// Ticks where |dF| exceeds this are part of a force step (the slew limit is 1 N/tick; a
// path's own force changes by a few hundredths of a newton per tick).
constexpr double kStepN = 0.1;
constexpr int kSettleTicks = 300;  // the first model has faded in

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"snapthread-snap-ahead-chart: snap position error vs server rate (issue 17)"};
  std::vector<std::string> scenes;
  std::vector<double> rates = {1000.0, 300.0, 100.0, 30.0};
  std::string out_path;
  double speed = 0.05;
  app.add_option("--scene", scenes, "scene YAML files")->required()->check(CLI::ExistingFile);
  app.add_option("--rates-hz", rates, "server update rates")->delimiter(',');
  app.add_option("--speed-m-per-s", speed, "sim-path hand speed")->check(CLI::PositiveNumber);
  app.add_option("--out", out_path, "CSV file")->required();
  CLI11_PARSE(app, argc, argv);
  std::FILE* out = std::fopen(out_path.c_str(), "w");
  if (out == nullptr) {
    std::fprintf(stderr, "snapthread-snap-ahead-chart: --out: cannot write %s\n", out_path.c_str());
    return 2;
  }
  std::fprintf(out, "scene,rate_hz,snap_ahead,snap,fold_m,error_ticks,jump_n,jumps,folds\n");
  const double tick_travel_m = speed * 1e-3;
  for (const std::string& file : scenes) {
    const snapthread::Scene scene = snapthread::LoadScene(file);
    const std::vector<Eigen::Vector3d> folds = TrueFolds(scene, 0.01);
    for (double rate : rates) {
      for (bool ahead : {true, false}) {
        SessionOptions o;
        o.server_hz = rate;
        o.snap_ahead = ahead;
        o.speed_m_per_s = speed;
        const auto run = RunSession(scene, o);
        const auto jumps = ForceJumps(run.ticks, kStepN, kSettleTicks);
        for (size_t k = 0; k < folds.size(); ++k) {
          double error = NAN, size = 0.0;
          if (k < jumps.size()) {
            const int t = jumps[k].tick;
            const Eigen::Vector3d v = run.ticks[t].position_m - run.ticks[t - 1].position_m;
            error = (jumps[k].position_m - folds[k]).dot(v.normalized()) / tick_travel_m;
            size = jumps[k].size_n;
          }
          std::fprintf(out, "%s,%g,%d,%zu,%.9g,%.3f,%.3f,%zu,%zu\n", scene.name.c_str(), rate,
                       ahead ? 1 : 0, k + 1, folds[k].norm(), error, size, jumps.size(), folds.size());
        }
        if (folds.empty()) {
          std::fprintf(out, "%s,%g,%d,0,nan,nan,0,%zu,0\n", scene.name.c_str(), rate, ahead ? 1 : 0,
                       jumps.size());
        }
      }
    }
  }
  std::fclose(out);
  return 0;
}
