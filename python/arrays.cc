#include "arrays.h"

#include <utility>

namespace snapthread::python {

namespace py = pybind11;

namespace {
// A capsule that deletes a heap-held T when the array that holds it goes away.
template <typename T>
py::capsule Owner(T* owned) {
  return py::capsule(owned, [](void* p) { delete static_cast<T*>(p); });
}
}  // namespace

py::array_t<double> TakeArray(std::vector<double>&& values) {
  auto* owned = new std::vector<double>(std::move(values));
  const py::capsule owner = Owner(owned);
  return py::array_t<double>({static_cast<py::ssize_t>(owned->size())}, owned->data(), owner);
}

py::array_t<std::int64_t> IntegerArray(const std::vector<double>& values) {
  py::array_t<std::int64_t> out(static_cast<py::ssize_t>(values.size()));
  auto view = out.mutable_unchecked<1>();
  for (size_t i = 0; i < values.size(); ++i) view(static_cast<py::ssize_t>(i)) = static_cast<std::int64_t>(values[i]);
  return out;
}

py::array_t<double> TakeNodes(Eigen::Matrix3Xd&& nodes) {
  auto* owned = new Eigen::Matrix3Xd(std::move(nodes));
  const py::capsule owner = Owner(owned);
  const auto k = static_cast<py::ssize_t>(owned->cols());
  return py::array_t<double>({k, py::ssize_t{3}}, owned->data(), owner);
}

}  // namespace snapthread::python
