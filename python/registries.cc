// SolverOptions, the solver registry and the model registry (with each model's parameter
// schema) as Python objects: what the scene keys `solver:` and `params:` accept.
#include <string>

#include <pybind11/stl.h>

#include "bindings.h"
#include "models/registry.h"
#include "solvers/options.h"
#include "solvers/registry.h"

namespace snapthread::python {

namespace py = pybind11;

namespace {

const char* KindName(ParamKind kind) {
  switch (kind) {
    case ParamKind::kNumber: return "number";
    case ParamKind::kInteger: return "integer";
    case ParamKind::kBool: return "bool";
  }
  return "number";
}

void BindSolverOptions(py::module_& m) {
  py::class_<SolverOptions>(m, "SolverOptions",
                            "How an equilibrium is solved: the method, when to stop, which linear algebra "
                            "(the scene's `solver:` keys). Assign fields, then pass it to Tracker.options.")
      .def(py::init<>(), "The defaults (a scene without a `solver:` key gets these).")
      .def_readwrite("method", &SolverOptions::method,
                     "A registered solver's name (snapthread.solvers(): newton, newton-ls, higher-order).")
      .def_readwrite("cutoff", &SolverOptions::cutoff,
                     "Stop when the internal force |E_x|_2 < cutoff (and, with a force tolerance, the "
                     "grasp force is certified to it).")
      .def_readwrite("force_tolerance", &SolverOptions::force_tolerance,
                     "Converged only when the certified force error is at most force_tolerance x the "
                     "model's force scale (or the floor force_floor_n); 0 = the cutoff alone.")
      .def_readwrite("force_floor_n", &SolverOptions::force_floor_n,
                     "Absolute floor of the force tolerance, newtons at the device (0 = none).")
      .def_readwrite("newtons_per_model_force", &SolverOptions::newtons_per_model_force,
                     "The scene's device.newtons_per_model_force (for force_floor_n).")
      .def_readwrite("max_iterations", &SolverOptions::max_iterations,
                     "Iteration budget per control update; 0 = unlimited.")
      .def_readwrite("max_time_us", &SolverOptions::max_time_us,
                     "Wall-clock budget per update in microseconds; 0 = none (a snap may then spread "
                     "over updates: termination snapping).")
      .def_readwrite("linear_solver", &SolverOptions::linear_solver,
                     "Linear algebra backend: auto, banded, cholmod or dense.")
      .def_readwrite("degeneracy_ratio", &SolverOptions::degeneracy_ratio,
                     "higher-order: near a fold when lambda_0 <= ratio x lambda_0 of the last regular state.")
      .def_readwrite("max_reduction_step", &SolverOptions::max_reduction_step,
                     "higher-order: cap on |s*| of the one-direction reduction, model units.")
      .def_readwrite("secant_predictor", &SolverOptions::secant_predictor,
                     "Warm-start each update from the tangent / secant predictor.")
      .def(
          "validate",
          [](const SolverOptions& o) {
            std::string error;
            if (!o.IsValid(&error)) throw py::value_error(error);
          },
          "Raise ValueError naming the first bad field (the method and linear solver names are "
          "checked when a tracker is made).")
      .def("__repr__", [](const SolverOptions& o) {
        return "SolverOptions(method='" + o.method + "', cutoff=" + py::repr(py::float_(o.cutoff)).cast<std::string>() +
               ", force_tolerance=" + py::repr(py::float_(o.force_tolerance)).cast<std::string>() +
               ", max_iterations=" + std::to_string(o.max_iterations) + ", linear_solver='" + o.linear_solver + "')";
      });
}

void BindSolverRegistry(py::module_& m) {
  py::class_<SolverEntry>(m, "SolverInfo", "A registered equilibrium method (SolverOptions.method).")
      .def_readonly("name", &SolverEntry::name, "The method's name.")
      .def_readonly("doc", &SolverEntry::doc, "One line on what it does.")
      .def("__repr__", [](const SolverEntry& e) { return "SolverInfo('" + e.name + "')"; });
  m.def(
      "solvers",
      [] {
        py::list out;
        for (const SolverEntry& e : SolverRegistry::Global().Entries())
          out.append(py::cast(&e, py::return_value_policy::reference));
        return out;
      },
      "The registered equilibrium methods, in registration order.");
}

void BindModelRegistry(py::module_& m) {
  py::class_<ParamSpec>(m, "ParamSpec", "One parameter of a model (the scene key params.<name>).")
      .def_readonly("name", &ParamSpec::name)
      .def_property_readonly("kind", [](const ParamSpec& p) { return KindName(p.kind); },
                             "'number', 'integer' or 'bool'.")
      .def_readonly("default", &ParamSpec::default_value, "The value a scene that does not set it gets.")
      .def_readonly("min", &ParamSpec::min)
      .def_readonly("min_inclusive", &ParamSpec::min_inclusive)
      .def_readonly("max", &ParamSpec::max)
      .def_readonly("max_inclusive", &ParamSpec::max_inclusive)
      .def_readonly("units", &ParamSpec::units, "'model length', ... ('' for a pure number).")
      .def_readonly("doc", &ParamSpec::doc, "One line, with the seed's equation where there is one.")
      .def("expected", &ParamSpec::Expected, "What a valid value is, e.g. 'an integer >= 2'.")
      .def("__repr__", [](const ParamSpec& p) { return "ParamSpec('" + p.name + "', " + p.Expected() + ")"; });
  py::class_<ModelRegistration>(m, "ModelInfo", "A registered model (the scene key `model:`).")
      .def_readonly("name", &ModelRegistration::name)
      .def_readonly("doc", &ModelRegistration::doc, "One line on the model.")
      .def_readonly("params", &ModelRegistration::params, "Its parameters (list of ParamSpec).")
      .def_property_readonly("is_chain", [](const ModelRegistration& r) { return r.capabilities.chain.has_value(); },
                             "A chain of segments (bench and advisor may re-discretise it).")
      .def("__repr__", [](const ModelRegistration& r) { return "ModelInfo('" + r.name + "')"; });
  m.def(
      "models",
      [] {
        py::list out;
        for (const ModelRegistration& r : Models()) out.append(py::cast(&r, py::return_value_policy::reference));
        return out;
      },
      "The registered models, built-ins first in registration order.");
  m.def(
      "find_model", [](const std::string& name) { return FindModel(name); }, py::arg("name"),
      py::return_value_policy::reference, "The model called `name`, or None.");
  m.def("model_help", &ModelHelp, "The models and their parameters as snapthread-sweep --help lists them.");
}

}  // namespace

void BindRegistries(py::module_& m) {
  BindSolverOptions(m);
  BindSolverRegistry(m);
  BindModelRegistry(m);
}

}  // namespace snapthread::python
