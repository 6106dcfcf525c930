// The rod's speed: median updates per second along the Greenhill
// path (scenes/rod_greenhill.yaml, 0 -> 720 degrees of roll in 2000 steps through the
// buckle) at several n, each from a fresh tracker (the reset is not timed).
#include <iomanip>
#include <ostream>
#include <string>

#include "bench.h"

namespace snapthread {

std::vector<RodSpeedRow> RunRodSpeedBench(const std::string& scenes_dir, const std::vector<int>& ns,
                                          int repetitions, std::ostream& log) {
  std::vector<RodSpeedRow> rows;
  for (int n : ns) {
    const Scene scene = LoadScene(scenes_dir + "/rod_greenhill.yaml", {{"params.n", std::to_string(n)}});
    const TimedSweep t = TimeSweep(scene, PathControls(scene, 2000), repetitions, 1.0);
    rows.push_back({n, t.rate_hz});
    log << "rod_greenhill n=" << n << " (" << scene.solver.method << "): median " << std::fixed
        << std::setprecision(1) << t.rate_hz.median / 1000.0 << " k updates/s (min " << t.rate_hz.min / 1000.0
        << ", max " << t.rate_hz.max / 1000.0 << ", " << t.rate_hz.count << " runs)\n"
        << std::defaultfloat;
  }
  return rows;
}

}  // namespace snapthread
