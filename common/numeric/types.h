// Basic numeric types shared by the physics core.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace snapthread {

using Vec = Eigen::VectorXd;
using Mat = Eigen::MatrixXd;
// Column-major, int indices: the layout CHOLMOD and Eigen's sparse solvers expect.
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

}  // namespace snapthread
