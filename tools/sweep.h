// Quasi-static sweeps of a scene along a straight control path (snapthread-sweep, the
// stability suite and the benchmarks share this).
#pragma once

#include <cstddef>
#include <functional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "scene/scene.h"
#include "solvers/registry.h"
#include "tracking/make_tracker.h"
#include "tracking/tracker.h"

namespace snapthread {

struct SweepSpec {
  Vec from, to;      // position part of the controls (2 or 3 entries)
  int steps = 100;   // N equal steps: rows 0..N
  bool back = false; // continue N more steps back to `from` (2N+1 rows)
};

struct SweepRow {
  int step = 0;
  Vec u;                 // full controls
  Vec force;             // F = -E_u
  Vec state;             // the equilibrium x
  double probe = 0.0, energy = 0.0, residual = 0.0, lambda_min = 0.0, solve_us = 0.0;
  // Certified force error of the row (SolverSummary::force_error, model force units; -1:
  // not estimated).
  double force_error = -1.0;
  int iterations = 0, gradient_evaluations = 0, hessian_evaluations = 0;
  int negative_pivots = 0;  // of E_xx at the equilibrium (its inertia)
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();  // GraspTorqueCapability, 0 without one
  bool snapped = false;
  EquilibriumStatus status = EquilibriumStatus::kRegular;
  Termination termination = Termination::kConverged;
};

// The control at each row of the sweep (the direction part of a gripped thread3d
// scene stays at the scene's grasp direction).
std::vector<Vec> SweepControls(const Scene& scene, const SweepSpec& spec);

// The scene's grasp.path (every grasp's), each leg cut into `steps_per_leg` equal steps (positions
// linear, grip directions normalised-linear); first waypoint first.
std::vector<Vec> PathControls(const Scene& scene, int steps_per_leg);

// Resets a tracker at the first control (solved to the cutoff) and updates it along
// the path. Row 0 is the reset state. on_row (optional) is told after each row how many
// are done, of how many: snapthread-sweep's progress at a terminal.
std::vector<SweepRow> RunSweep(EquilibriumTracker* tracker, const std::vector<Vec>& controls,
                               const std::function<void(size_t done, size_t total)>& on_row = {});

// One column of the sweep's table: its name in the CSV and one value per row, a number or
// a text. snapthread-sweep writes the table as CSV (WriteSweepCsv); the Python module's
// snapthread.sweep() hands the same columns over as NumPy arrays (python/).
struct SweepColumn {
  enum class Kind { kReal, kInteger, kText };
  std::string name{};
  Kind kind = Kind::kReal;
  std::vector<double> numbers{};     // kReal, kInteger (whole numbers)
  std::vector<std::string> texts{};  // kText
  int digits = 0;                  // significant digits in the CSV; 0: the writer's
};

// The columns of snapthread-sweep's CSV, in its order (WriteSweepCsv says which).
std::vector<SweepColumn> SweepColumns(const std::vector<SweepRow>& rows, const std::string& method,
                                      const GraspLayout& layout = {}, int num_grasps = 1);

// The CSV of snapthread-sweep (SweepColumns as text): header, then one line per row. The first columns are
// step,u_x,u_y,u_z,f_x,f_y,f_z,probe,energy,residual,iterations,method,lambda_min,snapped,solve_us
// A grasp that holds its orientation (layout.grip_rotation, the rod) adds, at the end,
// roll_deg (the x component of the grasp's rotation vector, degrees: the roll about the
// start tangent), t_x,t_y,t_z (GraspTorqueCapability: the torque of the model on the hand
// about the grasp point, world frame) and negative_pivots (the inertia of E_xx: an unstable equilibrium has > 0).
// A scene with several grasps keeps those columns for its first grasp and adds, at the
// end, u2_x,u2_y,u2_z,f2_x,f2_y,f2_z for the second (u3_*, f3_* for a third, ...).
// The last column is always force_error: the row's certified force error (max norm over
// the controls, model force units, -1 where none could be estimated; docs/accuracy.md).
// `digits`: significant digits of every number but solve_us (17 writes each double exactly).
void WriteSweepCsv(const std::vector<SweepRow>& rows, const std::string& method, std::ostream& out,
                   const GraspLayout& layout = {}, int num_grasps = 1, int digits = 12);

// Node positions of every row (Model::NodePositions): step,node,x,y,z, for drawing.
void WriteShapeCsv(const std::vector<SweepRow>& rows, const Model& model, std::ostream& out,
                   int digits = 9);

// Line colour of a registered method in the gnuplot charts (by registration order).
const char* MethodColor(std::string_view method);

// Parses "x,y[,z]" with `dim` finite numbers; throws std::invalid_argument naming `what`.
Vec ParsePoint(const std::string& text, int dim, const std::string& what);

}  // namespace snapthread
