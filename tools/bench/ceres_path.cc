// Ceres Solver on the thread3d path (built only when find_package(Ceres) succeeds).
//
// The same energy as the thread3d model, written as least squares (Ceres minimises
// 1/2 sum |r|^2):
//   stretching  gamma/2 (l - L)^2      = 1/2 r^2,    r = sqrt(gamma) (l - L)          (3.7)
//   bending     beta/2 (1 - w1.w2)     = 1/2 |r|^2,  r = sqrt(beta/2) (w1 - w2)       (3.6)
// (|w1 - w2|^2 = 2 - 2 w1.w2 for unit w), so the cost is E minus the model's constant
// shift -n beta B / 2. Every node is a 3-vector parameter block: p_0 and the grasp p_n
// constant, p_1 on the clamp axis (a SubsetManifold holds y_1 = z_1 = 0).
#include "path.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "linalg/linear_solver.h"
#include "models/models.h"

namespace snapthread {
namespace {

struct StretchResidual {
  double sqrt_gamma, rest;
  template <typename T>
  bool operator()(const T* a, const T* b, T* r) const {
    const T d0 = b[0] - a[0], d1 = b[1] - a[1], d2 = b[2] - a[2];
    r[0] = sqrt_gamma * (ceres::sqrt(d0 * d0 + d1 * d1 + d2 * d2) - rest);
    return true;
  }
};

struct BendResidual {
  double scale;  // sqrt(beta / 2)
  template <typename T>
  bool operator()(const T* a, const T* b, const T* c, T* r) const {
    T v1[3], v2[3];
    for (int k = 0; k < 3; ++k) {
      v1[k] = b[k] - a[k];
      v2[k] = c[k] - b[k];
    }
    const T l1 = ceres::sqrt(v1[0] * v1[0] + v1[1] * v1[1] + v1[2] * v1[2]);
    const T l2 = ceres::sqrt(v2[0] * v2[0] + v2[1] * v2[1] + v2[2] * v2[2]);
    for (int k = 0; k < 3; ++k) r[k] = scale * (v1[k] / l1 - v2[k] / l2);
    return true;
  }
};

// Stops Ceres at the project's rule: ||E_x||_2 below the cutoff (Ceres' gradient of
// 1/2 sum r^2 on the manifold is E_x in the free coordinates).
class GradientNormStop : public ceres::IterationCallback {
 public:
  explicit GradientNormStop(double cutoff) : cutoff_(cutoff) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    return s.gradient_norm < cutoff_ ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  double cutoff_;
};

// The thread as a Ceres problem; node blocks live in nodes_ (state <-> nodes below).
class CeresThread {
 public:
  explicit CeresThread(const ModelParams& p)
      : n_(p.Integer("n")),
        shift_(-n_ * p.Number("bending") * p.Number("reference_bend") / 2.0),
        nodes_(static_cast<size_t>(3 * (n_ + 1)), 0.0) {
    const double sqrt_gamma = std::sqrt(p.Number("stretching"));
    const double bend_scale = std::sqrt(p.Number("bending") / 2.0);
    const double rest = p.Number("segment_length");
    for (int i = 1; i <= n_; ++i) {
      problem_.AddResidualBlock(new ceres::AutoDiffCostFunction<StretchResidual, 1, 3, 3>(
                                    new StretchResidual{sqrt_gamma, rest}),
                                nullptr, Node(i - 1), Node(i));
    }
    for (int j = 1; j <= n_ - 1; ++j) {
      problem_.AddResidualBlock(new ceres::AutoDiffCostFunction<BendResidual, 3, 3, 3, 3>(
                                    new BendResidual{bend_scale}),
                                nullptr, Node(j - 1), Node(j), Node(j + 1));
    }
    problem_.SetParameterBlockConstant(Node(0));
    problem_.SetParameterBlockConstant(Node(n_));
    problem_.SetManifold(Node(1), new ceres::SubsetManifold(3, {1, 2}));
  }

  // x = [x_1, x_2, y_2, z_2, ..., z_{n-1}] (the model's state), u = p_n.
  void Set(const Vec& x, const Vec& u) {
    Node(1)[0] = x[0];
    Node(1)[1] = Node(1)[2] = 0.0;
    for (int i = 2; i <= n_ - 1; ++i) {
      for (int k = 0; k < 3; ++k) Node(i)[k] = x[1 + 3 * (i - 2) + k];
    }
    for (int k = 0; k < 3; ++k) Node(n_)[k] = u[k];
  }
  void Get(Vec* x) const {
    x->resize(3 * n_ - 5);
    (*x)[0] = nodes_[3];
    for (int i = 2; i <= n_ - 1; ++i) {
      for (int k = 0; k < 3; ++k) (*x)[1 + 3 * (i - 2) + k] = nodes_[3 * i + k];
    }
  }
  double Energy() {
    double cost = 0.0;
    problem_.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
    return cost + shift_;
  }
  ceres::Problem& problem() { return problem_; }

 private:
  double* Node(int i) { return nodes_.data() + 3 * i; }

  const int n_;
  const double shift_;
  std::vector<double> nodes_;
  ceres::Problem problem_;
};

double Microseconds(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::micro>(b - a).count();
}

// The Ceres options of a setting name (lm-* / dogleg-* with a linear solver suffix), a
// gradient-norm stop only (the caller adds the callback); false for an unknown name.
bool SetCeresOptions(const std::string& name, int max_iterations, ceres::Solver::Options* options) {
  options->minimizer_type = ceres::TRUST_REGION;
  // The settings: lm-* Levenberg-Marquardt, dogleg-* Powell's dogleg; *-dense-qr,
  // *-dense-cholesky dense QR / normal Cholesky (Ceres' advice for small problems),
  // *-sparse-cholmod / *-sparse-eigen sparse normal Cholesky through SuiteSparse or
  // Eigen (Ceres' advice for large sparse ones), *-cgnr Ceres' iterative solver.
  auto ends_with = [&](const std::string& tail) {
    return name.size() >= tail.size() && name.compare(name.size() - tail.size(), tail.size(), tail) == 0;
  };
  if (name.rfind("lm-", 0) == 0) {
    options->trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  } else if (name.rfind("dogleg-", 0) == 0) {
    options->trust_region_strategy_type = ceres::DOGLEG;
  } else {
    return false;
  }
  if (ends_with("-dense-qr")) {
    options->linear_solver_type = ceres::DENSE_QR;
  } else if (ends_with("-dense-cholesky")) {
    options->linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  } else if (ends_with("-sparse-cholmod")) {
    options->linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    options->sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  } else if (ends_with("-cgnr")) {
    options->linear_solver_type = ceres::CGNR;
    options->preconditioner_type = ceres::JACOBI;
  } else if (ends_with("-sparse-eigen")) {
    options->linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    options->sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  } else {
    return false;
  }
  options->max_num_iterations = max_iterations;
  // Only the gradient-norm callback stops a converging solve.
  options->function_tolerance = 0.0;
  options->parameter_tolerance = 0.0;
  options->gradient_tolerance = 0.0;
  options->num_threads = 1;
  options->logging_type = ceres::SILENT;
  return true;
}

}  // namespace

bool CeresBuilt() { return true; }

double CeresEnergy(const Scene& scene, const Vec& x, const Vec& u) {
  CeresThread thread(scene.params);
  thread.Set(x, u);
  return thread.Energy();
}

std::vector<std::string> CeresSolverNames(int n) {
  if (n <= 30) return {"lm-dense-qr", "lm-dense-cholesky", "dogleg-dense-qr"};
  // CGNR (conjugate gradients on the normal equations, Jacobi preconditioner) only
  // where a path finishes in minutes: with lambda_min ~1e-11 it needs hundreds of
  // iterations per solve.
  if (n <= 300) return {"lm-sparse-cholmod", "lm-sparse-eigen", "dogleg-sparse-cholmod", "lm-cgnr"};
  return {"lm-sparse-cholmod", "lm-sparse-eigen", "dogleg-sparse-cholmod"};
}

CeresPathResult RunCeresPath(const Scene& scene, const std::vector<Vec>& controls, const std::vector<Vec>& states,
                             const std::vector<Vec>& forces, const CeresSetting& setting) {
  CeresPathResult result;
  result.solver = setting.solver;
  result.cutoff = setting.cutoff;
  if (controls.empty() || states.size() != controls.size() || forces.size() != controls.size()) {
    result.note = "no rows";
    return result;
  }
  const auto model = MakeModel(scene.params);
  const double snap_distance = 0.1 * ChainSegmentLength(scene.params);
  CeresThread thread(scene.params);
  ceres::Solver::Options options;
  const std::string& name = setting.solver;
  if (!SetCeresOptions(name, setting.max_iterations, &options)) {
    result.note = "unknown Ceres setting '" + name + "'";
    return result;
  }
  GradientNormStop stop(setting.cutoff);
  options.callbacks.push_back(&stop);
  std::string why;
  if (!options.IsValid(&why)) {
    result.note = "invalid Ceres options: " + why;
    return result;
  }

  std::string error;
  auto factor = MakeLinearSolver("auto", model->NumStates(), model->HessianBandwidth(), &error);
  SparseMatrix h = model->HessianPattern();
  factor->Analyze(h);
  Vec x = model->InitialState(controls[0]), eu;
  std::vector<double> us, force_errors;
  long iterations = 0;
  double total_us = 0.0;
  for (size_t row = 0; row < controls.size(); ++row) {
    const Vec& u = controls[row];
    thread.Set(x, u);
    ceres::Solver::Summary summary;
    const auto t0 = std::chrono::steady_clock::now();
    ceres::Solve(options, &thread.problem(), &summary);
    const double t = Microseconds(t0, std::chrono::steady_clock::now());
    total_us += t;
    thread.Get(&x);
    const bool converged = summary.termination_type == ceres::USER_SUCCESS;
    if (row > 0) {
      us.push_back(t);
      iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
      if (!converged) ++result.rows_not_converged;
    }
    // The equilibrium Ceres found, judged with the project's model (not timed).
    model->ControlGradient(x, u, &eu);
    const double force_error = (-eu - forces[row]).lpNorm<Eigen::Infinity>() / model->ForceScale();
    const double distance = (x - states[row]).lpNorm<Eigen::Infinity>();
    model->Hessian(x, u, &h);
    const bool factored = factor->Factorize(h) == LinearSolverStatus::kSuccess;
    const bool saddle = !factored || factor->NegativePivots() > 0;
    if (row == 0) {
      result.start_on_saddle = saddle;
      result.start_state_distance = distance;
      result.start_negative_pivots = factored ? factor->NegativePivots() : -1;
      continue;  // row 0 starts cold for both; the path rows follow
    }
    force_errors.push_back(force_error);
    result.state_distance_max = std::max(result.state_distance_max, distance);
    if (distance > snap_distance) ++result.rows_other_equilibrium;
    if (saddle) ++result.rows_saddle;
    if (setting.time_limit_s > 0 && total_us > 1e6 * setting.time_limit_s && row + 1 < controls.size()) {
      result.stopped_at_row = static_cast<int>(row);
      break;
    }
  }
  const Spread errors = Summarize(force_errors);
  result.force_error_max = errors.max;
  result.force_error_median = errors.median;
  result.update_us = Summarize(us);
  result.iterations_per_update = us.empty() ? 0.0 : static_cast<double>(iterations) / us.size();
  result.note = name;
  result.ran = true;
  return result;
}

}  // namespace snapthread
