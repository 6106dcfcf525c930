// snapthread-snap-ahead-chart: the snap position error (in servo ticks of travel) against
// the server's update rate, with and without snap-ahead, for the given scenes
// (docs/snap-ahead.md). One CSV row per scene, rate, mode and snap; the sessions run on a
// fake clock (snap_session.h), so the numbers do not depend on the machine's load.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "scene/scene.h"
#include "snap_session.h"

namespace {

using snapthread::snap_ahead::ForceJumps;
using snapthread::snap_ahead::RunSession;
using snapthread::snap_ahead::SessionOptions;
using snapthread::snap_ahead::SnapErrorTicks;
using snapthread::snap_ahead::TrueFolds;

// Ticks where |dF| exceeds this are part of a force step (the slew limit is 1 N/tick; a
// path's own force changes by a few hundredths of a newton per tick).
constexpr double kStepN = 0.1;
// The same for the grip's torque (thread3d_loop: the loop's flip is felt mostly in the
// torque). Half the torque slew limit (0.02 N m/tick). The grip model has no rotational
// stiffness, so between updates the torque holds and then steps: measured up to
// 0.007 N m per update at 30 Hz on the way into thread3d_loop's folds, and the snap's
// 0.05 N m at the slew limit.
constexpr double kStepNm = 0.01;
constexpr int kSettleTicks = 300;  // the first model has faded in

// One row per servo tick: time along the path, pose and rendered force.
void WriteTrace(const std::string& prefix, const std::string& scene, double rate, bool ahead,
                const snapthread::snap_ahead::SessionResult& run) {
  const std::string path = prefix + "_" + scene + "_" + std::to_string(static_cast<int>(rate)) + "_" +
                           (ahead ? "1" : "0") + ".csv";
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) {
    std::fprintf(stderr, "snapthread-snap-ahead-chart: --trace: cannot write %s\n", path.c_str());
    return;
  }
  std::fprintf(f, "t_s,x_m,y_m,z_m,qw,qx,qy,qz,fx_n,fy_n,fz_n,tx_nm,ty_nm,tz_nm\n");
  for (size_t i = 0; i < run.ticks.size(); ++i) {
    const auto& t = run.ticks[i];
    std::fprintf(f, "%.3f,%.7f,%.7f,%.7f,%.7f,%.7f,%.7f,%.7f,%.5f,%.5f,%.5f,%.6f,%.6f,%.6f\n",
                 1e-3 * static_cast<double>(i), t.position_m[0], t.position_m[1], t.position_m[2],
                 t.orientation[0], t.orientation[1], t.orientation[2], t.orientation[3], t.force_n[0],
                 t.force_n[1], t.force_n[2], t.torque_nm[0], t.torque_nm[1], t.torque_nm[2]);
  }
  std::fclose(f);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"snapthread-snap-ahead-chart: snap position error vs server rate"};
  std::vector<std::string> scenes;
  std::vector<double> rates = {1000.0, 300.0, 100.0, 30.0};
  std::string out_path;
  double speed = 0.05;
  app.add_option("--scene", scenes, "scene YAML files")->required()->check(CLI::ExistingFile);
  app.add_option("--rates-hz", rates, "server update rates")->delimiter(',');
  app.add_option("--speed-m-per-s", speed, "sim-path hand speed")->check(CLI::PositiveNumber);
  app.add_option("--out", out_path, "CSV file")->required();
  std::string trace_prefix, log_level = "warn";
  app.add_option("--log-level", log_level, "the server parts' log (debug: each fold search)")
      ->check(CLI::IsMember({"debug", "info", "warn", "error"}));
  app.add_option("--trace", trace_prefix,
                 "also write each session's ticks to PREFIX_<scene>_<rate>_<snap-ahead 1/0>.csv");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;  // --help exits 0, bad arguments 2 (docs/cli.md)
  }
  spdlog::set_level(spdlog::level::from_str(log_level));
  std::FILE* out = std::fopen(out_path.c_str(), "w");
  if (out == nullptr) {
    std::fprintf(stderr, "snapthread-snap-ahead-chart: --out: cannot write %s\n", out_path.c_str());
    return 1;
  }
  std::fprintf(out, "scene,rate_hz,snap_ahead,snap,fold_s,error_ticks,jump_n,jump_nm,jumps,folds\n");
  for (const std::string& file : scenes) {
    const snapthread::Scene scene = snapthread::LoadScene(file);
    const std::vector<snapthread::Vec> folds = TrueFolds(scene, 0.01);
    for (double rate : rates) {
      for (bool ahead : {true, false}) {
        SessionOptions o;
        o.server_hz = rate;
        o.snap_ahead = ahead;
        o.speed_m_per_s = speed;
        const auto run = RunSession(scene, o);
        const auto jumps = ForceJumps(run.ticks, kStepN, kStepNm, kSettleTicks);
        if (!trace_prefix.empty()) WriteTrace(trace_prefix, scene.name, rate, ahead, run);
        for (size_t k = 0; k < folds.size(); ++k) {
          // fold_s: when the hand passed the fold (time along its path: tick i reads the
          // path at i ms), from the felt jump and its error.
          double error = NAN, size = 0.0, size_nm = 0.0, fold_s = NAN;
          if (k < jumps.size()) {
            error = SnapErrorTicks(scene, run.ticks, jumps[k], folds[k]);
            size = jumps[k].size_n;
            size_nm = jumps[k].size_nm;
            fold_s = 1e-3 * (jumps[k].tick - error);
          }
          std::fprintf(out, "%s,%g,%d,%zu,%.4f,%.3f,%.3f,%.4f,%zu,%zu\n", scene.name.c_str(), rate,
                       ahead ? 1 : 0, k + 1, fold_s, error, size, size_nm, jumps.size(), folds.size());
        }
        if (folds.empty()) {
          std::fprintf(out, "%s,%g,%d,0,nan,nan,0,0,%zu,0\n", scene.name.c_str(), rate, ahead ? 1 : 0,
                       jumps.size());
        }
      }
    }
  }
  std::fclose(out);
  return 0;
}
