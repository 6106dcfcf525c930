// snapthread-linear-bench: Factorize + Solve time of each LDL^T backend on banded SPD
// matrices with the bandwidth of a 3-D thread chain (thread3d couples nodes up to two
// apart, 3 coordinates per node: half-bandwidth 2*3 + 2 = 8), for growing n. The
// numbers set the "auto" rule in common/linalg/linear_solver.cc. With --thread3d the
// matrices are real thread3d Hessians instead (n is then the number of segments; the
// thread is compressed to 80% so the Hessian is indefinite, as near a buckle).
//
// Each cell is the median over samples; a sample times a batch of repetitions long
// enough (>= --min-sample-us) for the clock, divided by the batch size. The machine is
// shared, so medians, not means.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "linalg/linear_solver.h"
#include "models/models.h"

namespace snapthread {
namespace {

using Clock = std::chrono::steady_clock;

// Random SPD matrix (strict diagonal dominance) with the full band |i - j| <= b; with
// `ring`, also the corner entries (0, n-1): a closed chain, sparse but of bandwidth n-1.
SparseMatrix RandomSpdBand(int n, int b, bool ring, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> t;
  Vec diagonal = Vec::Ones(n);
  for (int j = 0; j < n; ++j) {
    for (int i = j + 1; i <= std::min(n - 1, j + b); ++i) {
      const double v = u(*rng);
      t.emplace_back(i, j, v);
      t.emplace_back(j, i, v);
      diagonal[i] += std::abs(v);
      diagonal[j] += std::abs(v);
    }
  }
  if (ring && n - 1 > b) {
    const double v = u(*rng);
    t.emplace_back(n - 1, 0, v);
    t.emplace_back(0, n - 1, v);
    diagonal[0] += std::abs(v);
    diagonal[n - 1] += std::abs(v);
  }
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, diagonal[i]);
  SparseMatrix a(n, n);
  a.setFromTriplets(t.begin(), t.end());
  a.makeCompressed();
  return a;
}

// The registry's chain in three dimensions (thread3d), with its default parameters
// and `segments` segments.
ModelParams SpatialChain(int segments) {
  for (const ModelRegistration& m : Models()) {
    const ModelParams defaults{.model = m.name};
    if (m.capabilities.chain && m.capabilities.grasp_layout(defaults).spatial_dimension == 3) {
      ModelParams p = defaults;
      p.Set(m.capabilities.chain->segments, segments);
      return p;
    }
  }
  throw std::logic_error("no chain model in three dimensions is registered");
}

// thread3d Hessian at a compressed, slightly perturbed state; *bandwidth as the model
// reports it.
SparseMatrix Thread3dHessian(int segments, std::mt19937* rng, int* bandwidth) {
  ModelParams p = SpatialChain(segments);
  const auto model = MakeModel(p);
  Vec u = Vec::Zero(model->NumControls());
  u[0] = 0.8 * segments * ChainSegmentLength(p);
  Vec x = model->InitialState(u);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int i = 0; i < x.size(); ++i) x[i] += noise(*rng);
  SparseMatrix h = model->HessianPattern();
  model->Hessian(x, u, &h);
  *bandwidth = model->HessianBandwidth();
  return h;
}

struct Cell {
  bool ran = false;
  double median_us = 0.0;
  double analyze_us = 0.0;
  int samples = 0;
  std::string note;
};

Cell Measure(const std::string& name, const SparseMatrix& a, const Vec& rhs, int bandwidth,
             double min_sample_us, double budget_s) {
  Cell cell;
  std::string error;
  auto solver = MakeLinearSolver(name, static_cast<int>(a.rows()), bandwidth, &error);
  if (solver == nullptr) {
    cell.note = error;
    return cell;
  }
  const auto t0 = Clock::now();
  if (solver->Analyze(a) != LinearSolverStatus::kSuccess) {
    cell.note = solver->message();
    return cell;
  }
  cell.analyze_us = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
  Vec x(a.rows());
  // Warm-up (first-call allocations) and the batch size.
  int batch = 1;
  for (;;) {
    const auto start = Clock::now();
    for (int k = 0; k < batch; ++k) {
      if (solver->Factorize(a) != LinearSolverStatus::kSuccess ||
          solver->Solve(rhs, &x) != LinearSolverStatus::kSuccess) {
        cell.note = "failed: " + solver->message();
        return cell;
      }
    }
    const double us = std::chrono::duration<double, std::micro>(Clock::now() - start).count();
    if (us >= min_sample_us || batch >= (1 << 20)) break;
    batch *= 2;
  }
  const double residual = (a * x - rhs).norm() / rhs.norm();
  if (!(residual < 1e-10)) {
    cell.note = "wrong solution (relative residual " + std::to_string(residual) + ")";
    return cell;
  }
  std::vector<double> samples;
  const auto begin = Clock::now();
  while (samples.size() < 5 ||
         (samples.size() < 201 &&
          std::chrono::duration<double>(Clock::now() - begin).count() < budget_s)) {
    const auto start = Clock::now();
    for (int k = 0; k < batch; ++k) {
      solver->Factorize(a);
      solver->Solve(rhs, &x);
    }
    samples.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count() /
                      batch);
  }
  std::nth_element(samples.begin(), samples.begin() + samples.size() / 2, samples.end());
  cell.median_us = samples[samples.size() / 2];
  cell.samples = static_cast<int>(samples.size());
  cell.ran = true;
  return cell;
}

}  // namespace
}  // namespace snapthread

int main(int argc, char** argv) {
  using namespace snapthread;
  constexpr int kMaxSize = 100000;  // largest matrix size (or thread3d segment count)
  CLI::App app{"Factorize+Solve time of the LDL^T backends on banded SPD matrices"};
  int bandwidth = 8;
  std::vector<int> sizes = {10, 30, 100, 300, 1000, 3000};
  int dense_max = 1000;
  double min_sample_us = 200.0;
  double budget_s = 0.5;
  bool csv = false;
  bool ring = false;
  bool thread3d = false;
  app.add_option("--bandwidth", bandwidth, "half-bandwidth b (thread3d: 8)")->check(CLI::NonNegativeNumber);
  app.add_option("--sizes", sizes, "matrix sizes n");
  app.add_option("--dense-max", dense_max, "largest n for the O(n^3) dense backend");
  app.add_option("--min-sample-us", min_sample_us, "shortest timed batch, microseconds");
  app.add_option("--budget-s", budget_s, "time budget per cell, seconds (>= 5 samples)");
  app.add_flag("--ring", ring, "close the chain: couple the first and last unknowns");
  app.add_flag("--thread3d", thread3d, "real thread3d Hessians; --sizes are segment counts");
  app.add_flag("--csv", csv, "print CSV instead of a table");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;  // --help exits 0, bad arguments 2 (docs/cli.md)
  }
  // Checked here, naming the flag: CLI11's range checks let "nan" through, and a size of
  // -5 or 10^9 would end in bad_alloc or minutes of allocation.
  const auto bad = [](const std::string& message) {
    std::fprintf(stderr, "snapthread-linear-bench: %s\n", message.c_str());
    return 2;
  };
  const int min_size = thread3d ? 2 : 1;  // thread3d: segments
  for (int size : sizes) {
    if (size < min_size || size > kMaxSize) {
      return bad("--sizes: expected sizes in [" + std::to_string(min_size) + ", " + std::to_string(kMaxSize) +
                 "], got " + std::to_string(size));
    }
  }
  if (bandwidth > kMaxSize) return bad("--bandwidth: expected at most " + std::to_string(kMaxSize));
  if (dense_max < 0) return bad("--dense-max: expected an integer >= 0");
  if (!(min_sample_us > 0.0 && min_sample_us <= 1e7)) return bad("--min-sample-us: expected a number in (0, 1e7]");
  if (!(budget_s > 0.0 && budget_s <= 3600.0)) return bad("--budget-s: expected seconds in (0, 3600]");

  const std::vector<std::string> backends = {"cholmod", "dense", "banded", "auto"};
  if (thread3d && ring) {
    std::fprintf(stderr, "--ring and --thread3d exclude each other\n");
    return 2;
  }
  if (csv) {
    std::printf("n,bandwidth,backend,chosen,median_us,analyze_us,samples\n");
  } else {
    if (thread3d) {
      std::printf("Factorize+Solve, median us (thread3d Hessians, 80%% compressed: indefinite)\n");
    } else {
      std::printf("Factorize+Solve, median us (half-bandwidth %d, full band%s, SPD)\n",
                  bandwidth, ring ? " + corner (ring)" : "");
    }
    std::printf("%8s", "n");
    for (const auto& b : backends) std::printf(" %14s", b.c_str());
    std::printf("  auto picks\n");
  }
  std::mt19937 rng(12345);
  for (int size : sizes) {
    int b = 0;  // the bandwidth "auto" is told, as a model would report it
    SparseMatrix a;
    if (thread3d) {
      a = Thread3dHessian(size, &rng, &b);
    } else {
      a = RandomSpdBand(size, std::min(bandwidth, size - 1), ring, &rng);
      b = ring ? size - 1 : std::min(bandwidth, size - 1);
    }
    const int n = static_cast<int>(a.rows());
    Vec rhs = Vec::Ones(n);
    std::string chosen;
    {
      std::string error;
      auto solver = MakeLinearSolver("auto", n, b, &error);
      chosen = solver ? std::string(solver->Name()) : error;
    }
    if (!csv) std::printf("%8d", n);
    for (const auto& name : backends) {
      Cell cell;
      const double band_work = static_cast<double>(n) * (b + 1.0) * (b + 1.0);
      if ((name == "dense" && n > dense_max) || (name == "banded" && band_work > 2e9)) {
        cell.note = "skipped";  // seconds per call: O(n^3) dense, O(n b^2) banded
      } else {
        cell = Measure(name, a, rhs, b, min_sample_us, budget_s);
      }
      if (csv) {
        if (cell.ran) {
          std::printf("%d,%d,%s,%s,%.3f,%.3f,%d\n", n, b, name.c_str(),
                      name == "auto" ? chosen.c_str() : name.c_str(), cell.median_us,
                      cell.analyze_us, cell.samples);
        }
      } else if (cell.ran) {
        std::printf(" %14.2f", cell.median_us);
      } else {
        std::printf(" %14s", cell.note.substr(0, 14).c_str());
      }
      std::fflush(stdout);
    }
    if (!csv) std::printf("  %s\n", chosen.c_str());
  }
  return 0;
}
