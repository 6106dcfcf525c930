// The pieces of the Python module `snapthread` (module.cc puts them together): each
// binds one part of the C++ core with its docstrings. The bindings call the library the
// programs use (scene loader, registries, tracker, sweep); they hold no physics.
#pragma once

#include <vector>

#include <pybind11/pybind11.h>

#include "scene/scene.h"

namespace snapthread::python {

// SolverOptions and the solver registry; the model registry and its parameter schemas.
void BindRegistries(pybind11::module_& m);
// Scene, load_scene, parse_scene.
void BindScene(pybind11::module_& m);
// Tracker, StepResult, Status, Termination, KnotInfo, identify_knot.
void BindTracker(pybind11::module_& m);
// sweep(): snapthread-sweep's table as NumPy arrays.
void BindSweep(pybind11::module_& m);

// Scene overrides from Python: None, a list of "key=value" texts (the CLI's --set), or a
// dict {key: value} (value written as YAML: True -> true, numbers and texts as they print).
// Throws SceneError for a malformed one.
std::vector<SceneOverride> OverridesFrom(const pybind11::handle& set);

}  // namespace snapthread::python
