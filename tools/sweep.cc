#include "sweep.h"

#include <cmath>
#include <iomanip>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "models/grasp_torque_capability.h"

namespace snapthread {

std::vector<Vec> SweepControls(const Scene& scene, const SweepSpec& spec) {
  const int m = static_cast<int>(scene.grasp_start.size());
  const int d = static_cast<int>(spec.from.size());
  if (spec.to.size() != d || d > m) throw std::invalid_argument("sweep: --from/--to size mismatch");
  if (spec.steps < 1) throw std::invalid_argument("sweep: --steps must be >= 1");
  std::vector<Vec> us;
  auto at = [&](double t) {
    Vec u = scene.grasp_start;
    u.head(d) = spec.from + t * (spec.to - spec.from);
    return u;
  };
  for (int i = 0; i <= spec.steps; ++i) us.push_back(at(static_cast<double>(i) / spec.steps));
  if (spec.back)
    for (int i = spec.steps - 1; i >= 0; --i) us.push_back(at(static_cast<double>(i) / spec.steps));
  return us;
}

std::vector<Vec> PathControls(const Scene& scene, int steps_per_leg) {
  if (scene.path.size() < 2) throw std::invalid_argument("sweep: the scene has no grasp.path with two or more points");
  if (steps_per_leg < 1) throw std::invalid_argument("sweep: --steps must be >= 1");
  const bool grip = scene.grasp_layout.grip_direction;
  std::vector<Vec> us{scene.path.front()};
  for (size_t k = 1; k < scene.path.size(); ++k) {
    const Vec& a = scene.path[k - 1];
    const Vec& b = scene.path[k];
    for (int i = 1; i <= steps_per_leg; ++i) {
      const double t = static_cast<double>(i) / steps_per_leg;
      Vec u = a + t * (b - a);
      if (grip) u.tail(3).normalize();
      us.push_back(u);
    }
  }
  return us;
}

std::vector<SweepRow> RunSweep(EquilibriumTracker* tracker, const std::vector<Vec>& controls,
                               const std::function<void(size_t done, size_t total)>& on_row) {
  std::vector<SweepRow> rows;
  rows.reserve(controls.size());
  const GraspTorqueCapability* const grasp_torque = tracker->model().grasp_torque();
  for (size_t i = 0; i < controls.size(); ++i) {
    const TrackResult& r = i == 0 ? tracker->Reset(controls[i]) : tracker->Update(controls[i]);
    SweepRow row;
    row.step = static_cast<int>(i);
    row.u = controls[i];
    row.force = r.force;
    row.state = tracker->state();
    row.probe = r.probe;
    row.energy = r.energy;
    row.residual = r.summary.residual;
    row.lambda_min = r.summary.lambda_min;
    row.solve_us = r.summary.solve_us;
    row.force_error = r.summary.force_error;
    row.iterations = r.summary.iterations;
    row.gradient_evaluations = r.summary.gradient_evaluations;
    row.hessian_evaluations = r.summary.hessian_evaluations;
    row.negative_pivots = r.summary.negative_pivots;
    if (grasp_torque != nullptr) grasp_torque->GraspTorque(row.state, row.u, &row.torque);
    row.snapped = i > 0 && r.snapped;
    row.status = r.summary.status;
    row.termination = r.summary.termination;
    rows.push_back(std::move(row));
    if (on_row) on_row(i + 1, controls.size());
  }
  return rows;
}

std::vector<SweepColumn> SweepColumns(const std::vector<SweepRow>& rows, const std::string& method,
                                      const GraspLayout& layout, int num_grasps) {
  using Kind = SweepColumn::Kind;
  std::vector<SweepColumn> columns;
  const auto add = [&](std::string name, Kind kind, const auto& value, int digits = 0) {
    SweepColumn c{.name = std::move(name), .kind = kind, .digits = digits};
    for (const SweepRow& r : rows) {
      if constexpr (std::is_convertible_v<decltype(value(r)), std::string>) {
        c.texts.emplace_back(value(r));
      } else {
        c.numbers.push_back(static_cast<double>(value(r)));
      }
    }
    columns.push_back(std::move(c));
  };
  const auto comp = [](const Vec& v, int i) { return i < v.size() ? v[i] : 0.0; };
  static constexpr const char* kAxes[] = {"x", "y", "z"};
  add("step", Kind::kInteger, [](const SweepRow& r) { return r.step; });
  // A planar row (two controls) has 0 in its z columns.
  for (const auto& [prefix, vec] : {std::pair{"u_", &SweepRow::u}, std::pair{"f_", &SweepRow::force}})
    for (int c = 0; c < 3; ++c)
      add(std::string(prefix) + kAxes[c], Kind::kReal,
          [&](const SweepRow& r) { return c == 2 && r.u.size() == 2 ? 0.0 : comp(r.*vec, c); });
  add("probe", Kind::kReal, [](const SweepRow& r) { return r.probe; });
  add("energy", Kind::kReal, [](const SweepRow& r) { return r.energy; });
  add("residual", Kind::kReal, [](const SweepRow& r) { return r.residual; });
  add("iterations", Kind::kInteger, [](const SweepRow& r) { return r.iterations; });
  add("method", Kind::kText, [&](const SweepRow&) { return method; });
  add("lambda_min", Kind::kReal, [](const SweepRow& r) { return r.lambda_min; });
  add("snapped", Kind::kInteger, [](const SweepRow& r) { return r.snapped ? 1 : 0; });
  add("solve_us", Kind::kReal, [](const SweepRow& r) { return r.solve_us; }, 4);
  add("status", Kind::kText, [](const SweepRow& r) { return std::string(ToString(r.status)); });
  add("termination", Kind::kText, [](const SweepRow& r) { return std::string(ToString(r.termination)); });
  add("gradient_evals", Kind::kInteger, [](const SweepRow& r) { return r.gradient_evaluations; });
  add("hessian_evals", Kind::kInteger, [](const SweepRow& r) { return r.hessian_evaluations; });
  if (layout.grip_rotation) {
    add("roll_deg", Kind::kReal, [&](const SweepRow& r) { return comp(r.u, 3) * 180.0 / std::numbers::pi; });
    for (int c = 0; c < 3; ++c)
      add(std::string("t_") + kAxes[c], Kind::kReal, [c](const SweepRow& r) { return r.torque[c]; });
    add("negative_pivots", Kind::kInteger, [](const SweepRow& r) { return r.negative_pivots; });
  }
  // Further grasps: u2_*, f2_*, u3_*, ... after every single-grasp column.
  const int m = layout.NumControls();
  for (int g = 2; g <= num_grasps; ++g) {
    for (const auto& [q, vec] : {std::pair{"u", &SweepRow::u}, std::pair{"f", &SweepRow::force}})
      for (int c = 0; c < 3; ++c)
        add(q + std::to_string(g) + '_' + kAxes[c], Kind::kReal, [&](const SweepRow& r) {
          return c < layout.spatial_dimension ? comp(r.*vec, (g - 1) * m + c) : 0.0;
        });
  }
  add("force_error", Kind::kReal, [](const SweepRow& r) { return r.force_error; });
  return columns;
}

void WriteSweepCsv(const std::vector<SweepRow>& rows, const std::string& method, std::ostream& out,
                   const GraspLayout& layout, int num_grasps, int digits) {
  const std::vector<SweepColumn> columns = SweepColumns(rows, method, layout, num_grasps);
  for (size_t k = 0; k < columns.size(); ++k) out << (k > 0 ? "," : "") << columns[k].name;
  out << '\n';
  for (size_t i = 0; i < rows.size(); ++i) {
    for (size_t k = 0; k < columns.size(); ++k) {
      const SweepColumn& c = columns[k];
      if (k > 0) out << ',';
      if (c.kind == SweepColumn::Kind::kText) {
        out << c.texts[i];
      } else if (c.kind == SweepColumn::Kind::kInteger) {
        out << static_cast<long long>(c.numbers[i]);
      } else {
        out << std::setprecision(c.digits > 0 ? c.digits : digits) << c.numbers[i];
      }
    }
    out << '\n';
  }
}

void WriteShapeCsv(const std::vector<SweepRow>& rows, const Model& model, std::ostream& out, int digits) {
  out << "step,node,x,y,z\n" << std::setprecision(digits);
  Eigen::Matrix3Xd nodes;
  for (const SweepRow& r : rows) {
    model.NodePositions(r.state, r.u, &nodes);
    for (Eigen::Index k = 0; k < nodes.cols(); ++k) {
      out << r.step << ',' << k << ',' << nodes(0, k) << ',' << nodes(1, k) << ',' << nodes(2, k) << '\n';
    }
  }
}

Vec ParsePoint(const std::string& text, int dim, const std::string& what) {
  std::vector<double> vals;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    try {
      size_t used = 0;
      const double v = std::stod(item, &used);
      if (used != item.size() || !std::isfinite(v)) throw std::invalid_argument(item);
      vals.push_back(v);
    } catch (const std::exception&) {
      throw std::invalid_argument(what + ": '" + item + "' is not a finite number");
    }
  }
  if (static_cast<int>(vals.size()) != dim)
    throw std::invalid_argument(what + ": expected " + std::to_string(dim) + " comma-separated numbers (" +
                                (dim == 2 ? "X,Y" : "X,Y,Z") + "), got '" + text + "'");
  return Eigen::Map<Vec>(vals.data(), dim);
}

const char* MethodColor(std::string_view method) {
  static constexpr const char* kPalette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2"};
  const auto& entries = SolverRegistry::Global().Entries();
  for (size_t i = 0; i < entries.size(); ++i) {
    if (entries[i].name == method) return kPalette[i % std::size(kPalette)];
  }
  return "#000000";
}

}  // namespace snapthread
