#include "solvers/options.h"

#include <cmath>

namespace snapthread {

bool SolverOptions::IsValid(std::string* error) const {
  auto fail = [&](const char* m) {
    if (error) *error = m;
    return false;
  };
  if (!(cutoff > 0.0) || !std::isfinite(cutoff)) return fail("solver.cutoff: expected a finite number > 0");
  if (!(force_tolerance >= 0.0) || !std::isfinite(force_tolerance))
    return fail("solver.force_tolerance: expected a finite number >= 0 (0 = stop on the cutoff alone)");
  if (!(force_floor_n >= 0.0) || !std::isfinite(force_floor_n))
    return fail("solver.force_floor_n: expected a finite number of newtons >= 0 (0 = none)");
  if (!(newtons_per_model_force > 0.0) || !std::isfinite(newtons_per_model_force))
    return fail("device.newtons_per_model_force: expected a finite number > 0");
  if (max_iterations < 0) return fail("solver.max_iterations: expected an integer >= 0 (0 = unlimited)");
  if (!(max_time_us >= 0.0) || !std::isfinite(max_time_us))
    return fail("solver.time_budget_us: expected a finite number >= 0 (0 = none)");
  if (!(degeneracy_ratio > 0.0 && degeneracy_ratio < 1.0))
    return fail("solver.degeneracy_ratio: expected a number in (0, 1)");
  if (!(max_reduction_step > 0.0) || !std::isfinite(max_reduction_step))
    return fail("solver.max_reduction_step: expected a finite number > 0");
  return true;
}

}  // namespace snapthread
