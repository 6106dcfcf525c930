// The Python module `snapthread` (docs/python.md): its compiled part, snapthread._snapthread,
// which snapthread/__init__.py re-exports.
#include <pybind11/pybind11.h>

#include "bindings.h"
#include "scene/input_file.h"

PYBIND11_MODULE(_snapthread, m) {
  namespace py = pybind11;
  m.doc() = "snapthread's scenes, registries, tracker and sweep (pybind11 over the C++ core).";
  // A bad scene is bad input (ValueError); a file that cannot be read is an OSError.
  py::register_exception<snapthread::SceneError>(m, "SceneError", PyExc_ValueError);
  py::register_exception<snapthread::InputFileError>(m, "InputFileError", PyExc_OSError);
  snapthread::python::BindRegistries(m);
  snapthread::python::BindScene(m);
  snapthread::python::BindTracker(m);
  snapthread::python::BindSweep(m);
}
