#include "stability_resolution.h"

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <numeric>

#include "sweep.h"
#include "topology/identify_knot.h"

namespace snapthread {

std::vector<ResolutionSweep> ResolutionSweeps(const std::string& dir) {
  std::vector<ResolutionSweep> s;
  for (int n : {60, 80, 100, 150})
    s.push_back({"knot_overhand_n" + std::to_string(n), dir + "/knot_overhand.yaml", n, 100, true});
  for (int n : {20, 50, 100})
    s.push_back({"rod_greenhill_n" + std::to_string(n), dir + "/rod_greenhill.yaml", n, 360, false});
  for (int n : {30, 60, 100})
    s.push_back({"rod_hockling_n" + std::to_string(n), dir + "/rod_hockling.yaml", n, 300, false});
  return s;
}

std::string RowRuns(const std::vector<int>& rows) {
  std::string out;
  for (size_t i = 0; i < rows.size();) {
    size_t j = i;
    while (j + 1 < rows.size() && rows[j + 1] == rows[j] + 1) ++j;
    if (!out.empty()) out += ',';
    out += std::to_string(rows[i]);
    if (j > i) {
      out += '-';
      out += std::to_string(rows[j]);
    }
    i = j + 1;
  }
  return out;
}

ResolutionRow RunResolution(const ResolutionSweep& sweep, const std::string& method) {
  Scene scene = LoadScene(sweep.scene_file, {{"params.n", std::to_string(sweep.n)}});
  scene.solver.method = method;
  auto tracker = MakeTracker(scene);
  const std::vector<Vec> controls = PathControls(scene, sweep.steps_per_leg);
  ResolutionRow r;
  r.sweep = sweep.name;
  r.method = method;
  r.n = sweep.n;
  r.rows = static_cast<int>(controls.size());
  std::vector<int> unconverged;
  std::vector<double> us;
  // The rows of snapthread-sweep --path (RunSweep's Reset, then Update), with the
  // tracker's count of the retry's sub-steps at each row.
  for (size_t i = 0; i < controls.size(); ++i) {
    const TrackResult& t = i == 0 ? tracker->Reset(controls[i]) : tracker->Update(controls[i]);
    if (i == 0) r.start_continuation_steps = tracker->start_continuation_steps();
    if (i > 0 && tracker->substeps() > 0) ++r.retried;
    if (t.summary.status == EquilibriumStatus::kFailed) ++r.failed;
    if (!t.summary.IsConverged()) unconverged.push_back(static_cast<int>(i));
    r.max_iterations = std::max(r.max_iterations, t.summary.iterations);
    us.push_back(t.summary.solve_us);
  }
  if (!us.empty()) {
    r.mean_us = std::accumulate(us.begin(), us.end(), 0.0) / static_cast<double>(us.size());
    std::nth_element(us.begin(), us.begin() + us.size() / 2, us.end());
    r.median_us = us[us.size() / 2];
  }
  r.unconverged = static_cast<int>(unconverged.size());
  r.unconverged_rows = RowRuns(unconverged);
  if (!unconverged.empty()) r.first_unconverged = unconverged.front();
  if (sweep.name_knot && !controls.empty()) {
    Eigen::Matrix3Xd nodes;
    tracker->model().NodePositions(tracker->state(), controls.back(), &nodes);
    std::vector<Eigen::Vector3d> points(nodes.cols());
    for (Eigen::Index k = 0; k < nodes.cols(); ++k) points[k] = nodes.col(k);
    const topology::KnotInfo knot = topology::IdentifyKnot(points);
    r.last_knot = knot.ok ? knot.name : "not identified";
  }
  return r;
}

void WriteResolutionCsv(const std::vector<ResolutionRow>& rows, std::ostream& out) {
  out << "sweep,n,method,rows,failed,unconverged,unconverged_rows,retried,last_knot,start_continuation_steps,"
         "max_iterations,median_us_per_update,mean_us_per_update\n";
  out << std::setprecision(6);
  for (const auto& r : rows)
    out << r.sweep << ',' << r.n << ',' << r.method << ',' << r.rows << ',' << r.failed << ',' << r.unconverged
        << ",\"" << r.unconverged_rows << "\"," << r.retried << ',' << r.last_knot << ','
        << r.start_continuation_steps << ',' << r.max_iterations << ',' << r.median_us << ',' << r.mean_us << '\n';
}

void PrintResolutionTable(const std::vector<ResolutionRow>& rows, std::ostream& out) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "%-20s %5s %-12s %5s %6s %11s %7s %-10s %5s %9s %9s  %s\n", "sweep", "n", "method",
                "rows", "failed", "unconverged", "retried", "last_knot", "cont", "median_us", "mean_us",
                "unconverged rows");
  out << buf;
  for (const auto& r : rows) {
    std::snprintf(buf, sizeof buf, "%-20s %5d %-12s %5d %6d %11d %7d %-10s %5d %9.0f %9.0f  %.200s\n",
                  r.sweep.c_str(), r.n, r.method.c_str(), r.rows, r.failed, r.unconverged, r.retried,
                  r.last_knot.empty() ? "-" : r.last_knot.c_str(), r.start_continuation_steps, r.median_us, r.mean_us,
                  r.unconverged_rows.c_str());
    out << buf;
  }
}

}  // namespace snapthread
