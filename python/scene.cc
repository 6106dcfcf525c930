// Scenes from Python: load_scene / parse_scene (the loader the programs use, with the
// CLI's --set overrides) and the Scene's fields.
#include <string>
#include <utility>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "models/registry.h"

namespace snapthread::python {

namespace py = pybind11;

std::vector<SceneOverride> OverridesFrom(const py::handle& set) {
  std::vector<SceneOverride> overrides;
  if (set.is_none()) return overrides;
  if (py::isinstance<py::str>(set)) {
    overrides.push_back(ParseOverride(set.cast<std::string>()));
    return overrides;
  }
  if (py::isinstance<py::dict>(set)) {
    for (const auto& [key, value] : set.cast<py::dict>()) {
      // YAML spells booleans in lower case; numbers and texts as Python prints them.
      const std::string text = py::isinstance<py::bool_>(value) ? (value.cast<bool>() ? "true" : "false")
                                                                 : py::str(value).cast<std::string>();
      overrides.push_back(ParseOverride(py::str(key).cast<std::string>() + "=" + text));
    }
    return overrides;
  }
  for (const py::handle item : set) overrides.push_back(ParseOverride(item.cast<std::string>()));
  return overrides;
}

namespace {

// Every parameter of the scene's model (set or default) as a Python value of its kind.
py::dict ParamsDict(const ModelParams& params) {
  py::dict out;
  const ModelRegistration* model = FindModel(params.model);
  if (model == nullptr) return out;
  for (const ParamSpec& spec : model->params) {
    const char* key = spec.name.c_str();
    switch (spec.kind) {
      case ParamKind::kBool: out[key] = params.Bool(spec.name); break;
      case ParamKind::kInteger: out[key] = params.Integer(spec.name); break;
      case ParamKind::kNumber: out[key] = params.Number(spec.name); break;
    }
  }
  return out;
}

// The scene's grasp.path as a (waypoints, controls) array (0 rows without a path).
Mat PathMatrix(const Scene& scene) {
  Mat path(static_cast<Eigen::Index>(scene.path.size()), scene.grasp_start.size());
  for (size_t k = 0; k < scene.path.size(); ++k) path.row(static_cast<Eigen::Index>(k)) = scene.path[k].transpose();
  return path;
}

}  // namespace

void BindScene(py::module_& m) {
  py::class_<GraspLayout>(m, "GraspLayout", "The controls of one grasp as a device sees them.")
      .def_readonly("spatial_dimension", &GraspLayout::spatial_dimension, "2 (planar) or 3.")
      .def_readonly("grip_direction", &GraspLayout::grip_direction, "A unit grip direction follows the position.")
      .def_readonly("grip_rotation", &GraspLayout::grip_rotation,
                    "A rotation vector (rad) follows the position: the grasp holds its orientation (the rod).")
      .def_property_readonly("num_controls", &GraspLayout::NumControls, "Controls of one grasp.");
  py::class_<Scene>(m, "Scene",
                    "A loaded, validated scene (scenes/*.yaml; docs/scenes.md lists the keys). Make one "
                    "with load_scene() or parse_scene().")
      .def_readonly("file", &Scene::file, "Where it was loaded from ('<string>' for text).")
      .def_readonly("name", &Scene::name)
      .def_readonly("description", &Scene::description)
      .def_property_readonly("model", [](const Scene& s) { return s.params.model; }, "The registered model's name.")
      .def_property_readonly("params", [](const Scene& s) { return ParamsDict(s.params); },
                             "Every parameter of the model, set or default: {name: value}.")
      .def_readonly("grasp_layout", &Scene::grasp_layout)
      .def_property_readonly(
          "grasps", [](const Scene& s) {
            std::vector<std::string> names;
            for (const SceneGrasp& g : s.grasps) names.push_back(g.name);
            return names;
          },
          "The grasps' names in the order of their controls ('' for the single grasp).")
      .def_readonly("grasp_start", &Scene::grasp_start, "The initial controls u (every grasp's, in order).")
      .def_property_readonly("path", &PathMatrix,
                             "The scripted grasp.path: one row of controls per waypoint (0 rows without one).")
      .def_readwrite("solver", &Scene::solver,
                     "The scene's SolverOptions (change a field here before making a Tracker).")
      .def_property_readonly("newtons_per_model_force",
                             [](const Scene& s) { return s.device.newtons_per_model_force; },
                             "The device mapping's force unit: newtons per model force unit.")
      .def("__repr__", [](const Scene& s) { return "Scene('" + s.file + "', model='" + s.params.model + "')"; });
  m.def(
      "load_scene",
      [](const std::string& path, const py::object& set) { return LoadScene(path, OverridesFrom(set)); },
      py::arg("path"), py::arg("set") = py::none(),
      "Load a scene file. `set` overrides keys as snapthread-sweep's --set does: a list of "
      "'key=value' texts (e.g. ['params.n=20', 'solver.method=newton']) or a dict "
      "{'params.n': 20}. Raises SceneError naming the file and the key for a bad scene.");
  m.def(
      "parse_scene",
      [](const std::string& text, const std::string& label, const py::object& set) {
        return ParseScene(text, label, OverridesFrom(set));
      },
      py::arg("text"), py::arg("label") = "<string>", py::arg("set") = py::none(),
      "A scene from YAML text (`label` names it in error messages); `set` as for load_scene.");
}

}  // namespace snapthread::python
