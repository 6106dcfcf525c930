#include "stability.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>

namespace snapthread {
namespace {

Vec Point(double x, double y) {
  Vec u(2);
  u << x, y;
  return u;
}

// Straight legs through waypoints, `n` rows per leg.
std::vector<Vec> Legs(const std::vector<Vec>& pts, int n) {
  std::vector<Vec> us{pts.front()};
  for (size_t k = 1; k < pts.size(); ++k)
    for (int i = 1; i <= n; ++i) us.push_back(pts[k - 1] + (static_cast<double>(i) / n) * (pts[k] - pts[k - 1]));
  return us;
}

// `turns` loops around (cx, cy) of radius r starting at angle -90 degrees (below the
// centre), counter-clockwise when ccw, `n` rows per turn.
std::vector<Vec> Circle(double cx, double cy, double r, double turns, bool ccw, int n) {
  std::vector<Vec> us;
  const int rows = static_cast<int>(turns * n);
  for (int i = 0; i <= rows; ++i) {
    const double a = -M_PI / 2 + (ccw ? 1 : -1) * 2 * M_PI * i / n;
    us.push_back(Point(cx + r * std::cos(a), cy + r * std::sin(a)));
  }
  return us;
}

}  // namespace

std::vector<StandardSweep> StandardSweeps(const std::string& dir) {
  std::vector<StandardSweep> s;
  // Zeeman machine (2.4): folds at X = +-0.570 for Y = 3; the lower cusp at
  // (0, (3+sqrt 33)/4) = (0, 2.186).
  s.push_back({"zeeman_folds", dir + "/zeeman.yaml", "X -1 -> 1 -> -1 at Y = 3 (both folds, hysteresis)",
               Legs({Point(-1, 3), Point(1, 3), Point(-1, 3)}, 1000), 0, 0.002});
  s.push_back({"zeeman_loop_cw", dir + "/zeeman.yaml",
               "two clockwise loops of radius 0.9 around (0, 2.7), enclosing the cusp point",
               Circle(0, 2.7, 0.9, 2, false, 2800), 0, 2 * M_PI * 0.9 / 2800});
  s.push_back({"zeeman_loop_ccw", dir + "/zeeman.yaml", "the same loops counter-clockwise",
               Circle(0, 2.7, 0.9, 2, true, 2800), 0, 2 * M_PI * 0.9 / 2800});
  // Standard cusp (2.9): folds on 27 X^2 = -4 Y^3.
  s.push_back({"cusp_folds", dir + "/cusp.yaml", "X -1 -> 1 -> -1 at Y = -1 (folds at X = +-0.385)",
               Legs({Point(-1, -1), Point(1, -1), Point(-1, -1)}, 1000), 0, 0.002});
  s.push_back({"cusp_through", dir + "/cusp.yaml",
               "X -0.5 -> 0.5 at Y = 0: through the cusp point, E_TT = 0 at X = 0, no jump",
               Legs({Point(-0.5, 0), Point(0.5, 0)}, 500), 0, 0.002});
  s.push_back({"cusp_loop_cw", dir + "/cusp.yaml", "two clockwise loops of radius 1 around (0, -0.5)",
               Circle(0, -0.5, 1.0, 2, false, 3000), 0, 2 * M_PI / 3000});
  s.push_back({"cusp_loop_ccw", dir + "/cusp.yaml", "the same loops counter-clockwise",
               Circle(0, -0.5, 1.0, 2, true, 3000), 0, 2 * M_PI / 3000});
  // The tape of Fig 2.1: compressed to X = 9, snaps at Y = +-3.41.
  s.push_back({"curve2d_snap", dir + "/curve2d_snap.yaml", "Y -4 -> 4 -> -4 at X = 9 (both snaps)",
               Legs({Point(9, -4), Point(9, 4), Point(9, -4)}, 4000), 1, 0.002});
  // The 3D thread: the grip turns two full turns and back; the loop flips over.
  {
    const Scene scene = LoadScene(dir + "/thread3d_loop.yaml");
    s.push_back({"thread3d_loop", dir + "/thread3d_loop.yaml",
                 "grip turned 0 -> 720 -> 0 degrees about z at (7, 0.5, 1), 0.5 degree steps",
                 PathControls(scene, 60), 0, M_PI / 360});
  }
  // The rod: Greenhill's twist buckling, the grasp rolled through the buckle;
  // the charted component is the torque about the rod's axis (F's rotation part).
  {
    const Scene scene = LoadScene(dir + "/rod_greenhill.yaml");
    s.push_back({"rod_greenhill", dir + "/rod_greenhill.yaml",
                 "grasp rolled 0 -> 720 degrees about the rod's axis (buckles near 525), 2 degree steps",
                 PathControls(scene, 360), 3, M_PI / 90});
  }
  return s;
}

std::vector<SweepRow> ReferenceTrace(const Scene& scene_in, const std::vector<Vec>& controls, int substeps,
                                     int max_iterations) {
  Scene scene = scene_in;
  scene.solver.method = "newton-ls";
  scene.solver.cutoff = 1e-10;
  scene.solver.max_iterations = max_iterations;
  std::vector<Vec> fine{controls.front()};
  for (size_t i = 1; i < controls.size(); ++i)
    for (int k = 1; k <= substeps; ++k) {
      Vec u = controls[i - 1] + (static_cast<double>(k) / substeps) * (controls[i] - controls[i - 1]);
      if (scene.grasp_layout.grip_direction) u.tail(3).normalize();
      if (k == substeps) u = controls[i];
      fine.push_back(u);
    }
  auto tracker = MakeTracker(scene);
  const auto all = RunSweep(tracker.get(), fine);
  std::vector<SweepRow> rows;
  rows.reserve(controls.size());
  bool snapped_since_row = false;
  for (size_t j = 0; j < all.size(); ++j) {
    snapped_since_row = snapped_since_row || all[j].snapped;
    if (j % substeps == 0) {
      SweepRow r = all[j];
      r.step = static_cast<int>(j / substeps);
      r.snapped = snapped_since_row;
      snapped_since_row = false;
      rows.push_back(r);
    }
  }
  return rows;
}

int CountReversals(const std::vector<SweepRow>& rows, int component, double tolerance) {
  if (rows.empty()) return 0;
  const int m = static_cast<int>(rows.front().force.size());
  int total = 0;
  for (int c = 0; c < m; ++c) {
    if (component >= 0 && c != component) continue;
    // A zig-zag filter: a reversal is a move of more than `tolerance` back from the
    // last extreme, so wiggles at the convergence cutoff's noise level do not count.
    int dir = 0;
    double extreme = rows.front().force[c];
    for (size_t i = 1; i < rows.size(); ++i) {
      const double f = rows[i].force[c];
      if (dir >= 0 && f > extreme) {
        extreme = f;
        if (dir == 0 && f - rows.front().force[c] > tolerance) dir = 1;
      } else if (dir <= 0 && f < extreme) {
        extreme = f;
        if (dir == 0 && rows.front().force[c] - f > tolerance) dir = -1;
      } else if (dir > 0 && f < extreme - tolerance) {
        ++total;
        dir = -1;
        extreme = f;
      } else if (dir < 0 && f > extreme + tolerance) {
        ++total;
        dir = 1;
        extreme = f;
      }
    }
  }
  return total;
}

double ReversalTolerance(const std::vector<SweepRow>& ref) {
  double lo = 0.0, hi = 0.0;
  bool first = true;
  for (const auto& r : ref)
    for (int c = 0; c < r.force.size(); ++c) {
      lo = first ? r.force[c] : std::min(lo, r.force[c]);
      hi = first ? r.force[c] : std::max(hi, r.force[c]);
      first = false;
    }
  return 1e-3 * std::max(hi - lo, 1e-12);
}

StabilityRow Compare(const std::vector<SweepRow>& trace, const std::vector<SweepRow>& ref) {
  StabilityRow r;
  const double tol = ReversalTolerance(ref);
  r.reversals = CountReversals(trace, -1, tol);
  r.reference_reversals = CountReversals(ref, -1, tol);
  r.spurious_reversals = std::max(0, r.reversals - r.reference_reversals);
  std::vector<int> snaps, ref_snaps;
  for (const auto& row : trace)
    if (row.snapped) snaps.push_back(row.step);
  for (const auto& row : ref)
    if (row.snapped) ref_snaps.push_back(row.step);
  r.snaps = static_cast<int>(snaps.size());
  r.reference_snaps = static_cast<int>(ref_snaps.size());
  for (int rs : ref_snaps) {
    int best = -1;
    for (int s : snaps)
      if (best < 0 || std::abs(s - rs) < best) best = std::abs(s - rs);
    if (best < 0 || best > 50) {
      r.snap_error_steps = -1;  // missed
      break;
    }
    r.snap_error_steps = std::max(r.snap_error_steps, best);
  }
  for (int s : snaps) {
    bool near = false;
    for (int rs : ref_snaps) near = near || std::abs(s - rs) <= 1;
    if (!near) ++r.extra_snaps;
  }
  double sum2 = 0.0;
  const size_t n = std::min(trace.size(), ref.size());
  for (size_t i = 0; i < n; ++i) {
    const double e = (trace[i].force - ref[i].force).norm();
    r.force_error_max = std::max(r.force_error_max, e);
    sum2 += e * e;
    r.state_error_max = std::max(r.state_error_max, std::abs(trace[i].probe - ref[i].probe));
    r.mean_gradients += trace[i].gradient_evaluations;
    r.mean_hessians += trace[i].hessian_evaluations;
    r.mean_us += trace[i].solve_us;
  }
  if (n > 0) {
    r.force_error_rms = std::sqrt(sum2 / n);
    r.mean_gradients /= n;
    r.mean_hessians /= n;
    r.mean_us /= n;
  }
  return r;
}

void WriteStabilityCsv(const std::vector<StabilityRow>& rows, std::ostream& out) {
  out << "sweep,method,budget,reversals,reference_reversals,spurious_reversals,snaps,reference_snaps,"
         "snap_error_steps,extra_snaps,force_error_max,force_error_rms,state_error_max,gradients_per_update,"
         "hessians_per_update,us_per_update\n";
  out << std::setprecision(6);
  for (const auto& r : rows)
    out << r.sweep << ',' << r.method << ',' << r.budget << ',' << r.reversals << ','
        << r.reference_reversals << ',' << r.spurious_reversals << ',' << r.snaps << ',' << r.reference_snaps << ','
        << r.snap_error_steps << ',' << r.extra_snaps << ',' << r.force_error_max << ',' << r.force_error_rms << ','
        << r.state_error_max << ',' << r.mean_gradients << ',' << r.mean_hessians << ',' << r.mean_us << '\n';
}

void PrintStabilityTable(const std::vector<StabilityRow>& rows, std::ostream& out) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%-16s %-12s %6s %9s %6s %9s %6s %11s %11s %7s %7s\n", "sweep", "method", "budget",
                "spurious", "snaps", "snap_err", "extra", "|dF|max", "|dF|rms", "grad/up", "hess/up");
  out << buf;
  for (const auto& r : rows) {
    const std::string budget = r.budget == 0 ? "inf" : std::to_string(r.budget);
    const std::string snap_err = r.snap_error_steps < 0 ? "missed" : std::to_string(r.snap_error_steps);
    std::snprintf(buf, sizeof buf, "%-16s %-12s %6s %9d %3d/%-2d %9s %6d %11.3e %11.3e %7.2f %7.2f\n",
                  r.sweep.c_str(), r.method.c_str(), budget.c_str(), r.spurious_reversals, r.snaps,
                  r.reference_snaps, snap_err.c_str(), r.extra_snaps, r.force_error_max, r.force_error_rms,
                  r.mean_gradients, r.mean_hessians);
    out << buf;
  }
}

}  // namespace snapthread
