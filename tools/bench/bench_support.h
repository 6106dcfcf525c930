// Helpers shared by the bench's charts (internal to tools/bench/).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

#include "bench.h"

namespace snapthread {

using Clock = std::chrono::steady_clock;

inline double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

inline std::string BudgetText(int budget) { return budget == 0 ? "inf" : std::to_string(budget); }

std::string Sci(double v, int digits = 2);

// Relative rms force error of a trace against a reference of the same rows.
double RelativeRmsForceError(const std::vector<SweepRow>& trace, const std::vector<SweepRow>& ref, double scale);

double ForceScaleOf(const Scene& scene);

// The scene solved with `method`, `cutoff` and an iteration budget (0 = unlimited).
Scene WithSolver(const Scene& scene, const std::string& method, double cutoff, int budget);

// Child processes of the service and flood charts (service.cc).
// The whole file ("" when it cannot be read).
std::string ReadFile(const std::string& path);
// Starts argv[0] with stdout and stderr into `log`; returns the pid or -1.
pid_t Spawn(const std::vector<std::string>& args, const std::string& log);
// Waits for pid up to `timeout_s`; returns its exit status, or -1 after killing it.
int WaitFor(pid_t pid, double timeout_s);

}  // namespace snapthread
