// snapthread.sweep(): snapthread-sweep's run (the same scene loading, controls, tracker
// and table: tools/sweep.h) with its CSV's columns as NumPy arrays.
#include <algorithm>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "arrays.h"
#include "bindings.h"
#include "solvers/registry.h"
#include "sweep.h"

namespace snapthread::python {

namespace py = pybind11;

namespace {

// The table's columns keyed by the CSV's names, in its order: numbers as float64, whole
// numbers (step, iterations, snapped, ...) as int64, texts (method, status, termination)
// as NumPy str arrays.
py::dict ColumnsDict(std::vector<SweepColumn>&& columns) {
  using namespace pybind11::literals;
  py::dict out;
  const py::module_ numpy = py::module_::import("numpy");
  for (SweepColumn& c : columns) {
    switch (c.kind) {
      case SweepColumn::Kind::kReal: out[c.name.c_str()] = TakeArray(std::move(c.numbers)); break;
      case SweepColumn::Kind::kInteger: out[c.name.c_str()] = IntegerArray(c.numbers); break;
      case SweepColumn::Kind::kText: out[c.name.c_str()] = numpy.attr("array")(py::cast(c.texts), "dtype"_a = "str"); break;
    }
  }
  return out;
}

// The controls snapthread-sweep would follow: the scene's grasp.path (`steps` per leg) or
// the straight line from `start` to `end` (`steps` steps, and back with `back`).
std::vector<Vec> Controls(const Scene& scene, bool path, const std::optional<Vec>& start, const std::optional<Vec>& end,
                          std::optional<int> steps, bool back) {
  SweepSpec spec;
  spec.steps = steps.value_or(spec.steps);
  if (spec.steps < 1) throw std::invalid_argument("steps: expected an integer >= 1");
  if (path) {
    if (start || end) throw std::invalid_argument("start/end: not with path=True");
    if (back) throw std::invalid_argument("back: not with path=True (write the way back into the path)");
    return PathControls(scene, spec.steps);
  }
  if (!start || !end) throw std::invalid_argument("start and end, or path=True: one of them is required");
  const int dim = scene.grasp_layout.spatial_dimension;
  if (start->size() != dim || end->size() != dim)
    throw std::invalid_argument("start/end: expected " + std::to_string(dim) + " numbers (the grasp's position)");
  spec.from = *start;
  spec.to = *end;
  spec.back = back;
  return SweepControls(scene, spec);
}

py::dict Sweep(const std::string& scene_file, bool path, const std::optional<Vec>& start,
               const std::optional<Vec>& end, std::optional<int> steps, const std::optional<std::string>& method,
               const py::object& set, bool back) {
  Scene scene = LoadScene(scene_file, OverridesFrom(set));
  if (method) {
    if (SolverRegistry::Global().Find(*method) == nullptr)
      throw std::invalid_argument("method: expected " + SolverRegistry::Global().NamesText(", ", " or ") + ", got '" +
                                  *method + "'");
    scene.solver.method = *method;
  }
  const std::vector<Vec> controls = Controls(scene, path, start, end, steps, back);
  std::vector<SweepColumn> columns;
  {
    py::gil_scoped_release release;
    auto tracker = MakeTracker(scene);
    const std::vector<SweepRow> rows = RunSweep(tracker.get(), controls);
    const int grasps = std::max<int>(1, static_cast<int>(scene.grasps.size()));
    columns = SweepColumns(rows, scene.solver.method, scene.grasp_layout, grasps);
  }
  return ColumnsDict(std::move(columns));
}

// The controls as a (rows, controls) array.
Mat ControlsMatrix(const std::vector<Vec>& controls) {
  Mat out(static_cast<Eigen::Index>(controls.size()), controls.empty() ? 0 : controls.front().size());
  for (size_t i = 0; i < controls.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = controls[i].transpose();
  return out;
}

}  // namespace

void BindSweep(py::module_& m) {
  m.def(
      "path_controls",
      [](const Scene& scene, std::optional<int> steps) { return ControlsMatrix(Controls(scene, true, {}, {}, steps, false)); },
      py::arg("scene"), py::arg("steps") = py::none(),
      "The controls sweep(path=True) follows: the scene's grasp.path, each leg cut into `steps` "
      "equal steps (default 100), one row per update (row 0: the start). Step a Tracker through "
      "them to follow the sweep's path.");
  m.def("sweep", &Sweep, py::arg("scene_file"), py::arg("path") = false, py::arg("start") = py::none(),
        py::arg("end") = py::none(), py::arg("steps") = py::none(), py::arg("method") = py::none(),
        py::arg("set") = py::none(), py::arg("back") = false,
        R"(Quasi-static sweep of a scene: snapthread-sweep's run, its CSV's columns as NumPy arrays.

sweep(scene_file, path=True) is `snapthread-sweep --scene scene_file --path`; with start and end
(the grasp's position, 2 or 3 numbers) it is --from/--to, back=True adds --back. steps: per leg
with path (default 100, as the CLI). method: a registered solver (default: the scene's).
set: scene overrides, a list of 'key=value' or a dict, as --set. Returns a dict keyed by the CSV
header (step, u_x, ..., force_error): float64 and int64 arrays, str arrays for method, status and
termination. Releases the GIL while it solves.)");
}

}  // namespace snapthread::python
