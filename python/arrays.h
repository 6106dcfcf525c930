// NumPy arrays from the core's results without a copy of the numbers: the array takes
// over the C++ storage (moved into a capsule that the array owns and frees).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <pybind11/numpy.h>

namespace snapthread::python {

// A 1-D float64 array that owns `values`.
pybind11::array_t<double> TakeArray(std::vector<double>&& values);
// A 1-D int64 array of whole numbers (the table's integer columns).
pybind11::array_t<std::int64_t> IntegerArray(const std::vector<double>& values);
// Node positions as a (k, 3) C-ordered float64 array that owns `nodes`: a 3 x k
// column-major matrix is already k rows of (x, y, z) in memory.
pybind11::array_t<double> TakeNodes(Eigen::Matrix3Xd&& nodes);

}  // namespace snapthread::python
