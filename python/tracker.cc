// The tracker from Python: one scene's equilibrium followed along the controls a script
// gives, with the force, its stiffness, the status and the certified force error of each
// update; the shape as node positions and, for curves, its knot type.
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "arrays.h"
#include "bindings.h"
#include "models/registry.h"
#include "topology/identify_knot.h"
#include "tracking/make_tracker.h"

namespace snapthread::python {

namespace py = pybind11;

namespace {

// One scene's tracker. Its calls run without the GIL (another Python thread may run
// meanwhile), one at a time (the mutex: two threads stepping one tracker wait in turn).
class PyTracker {
 public:
  explicit PyTracker(const Scene& scene) : scene_(scene), tracker_(MakeTracker(scene_)) {
    py::gil_scoped_release release;
    tracker_->Reset(scene_.grasp_start);
  }

  TrackResult Reset(const Vec& u) {
    py::gil_scoped_release release;
    const std::lock_guard lock(mutex_);
    return tracker_->Reset(u);
  }
  TrackResult Step(const Vec& u) {
    py::gil_scoped_release release;
    const std::lock_guard lock(mutex_);
    return tracker_->Update(u);
  }
  TrackResult Resume(const Vec& x, const Vec& u) {
    py::gil_scoped_release release;
    const std::lock_guard lock(mutex_);
    return tracker_->Resume(x, u);
  }
  py::array_t<double> Nodes() {
    Eigen::Matrix3Xd nodes;
    {
      const std::lock_guard lock(mutex_);
      tracker_->model().NodePositions(tracker_->state(), tracker_->control(), &nodes);
    }
    return TakeNodes(std::move(nodes));
  }
  // Curves only (chains and every model in space), as the server's knot watch decides;
  // zeeman and cusp have no knot type.
  std::optional<topology::KnotInfo> Knot() {
    const Model& model = tracker_->model();
    if (!IsChain(scene_.params) && model.SpatialDimension() != 3) return std::nullopt;
    Eigen::Matrix3Xd nodes;
    {
      const std::lock_guard lock(mutex_);
      model.NodePositions(tracker_->state(), tracker_->control(), &nodes);
    }
    py::gil_scoped_release release;
    return topology::IdentifyKnotXyz(std::span<const double>(nodes.data(), static_cast<size_t>(nodes.size())));
  }
  void SetOptions(const SolverOptions& options) {
    const std::lock_guard lock(mutex_);
    tracker_->SetOptions(options);
  }

  const Scene& scene() const { return scene_; }
  const EquilibriumTracker& tracker() const { return *tracker_; }

 private:
  Scene scene_;
  std::unique_ptr<EquilibriumTracker> tracker_;
  std::mutex mutex_;
};

// str() of an enum value: the text the sweep CSV and the server's messages use. Set as
// the attribute itself (a .def would only add an overload after pybind11's own __str__).
template <typename Enum>
void TextAsStr(py::enum_<Enum>& e) {
  e.attr("__str__") = py::cpp_function([](Enum v) { return ToString(v); }, py::name("__str__"), py::is_method(e));
}

void BindStatuses(py::module_& m) {
  py::enum_<EquilibriumStatus> status(m, "Status",
                                      "What the equilibrium looks like to a user of the force (str() gives "
                                      "the sweep CSV's text).");
  status.value("regular", EquilibriumStatus::kRegular)
      .value("near_fold", EquilibriumStatus::kNearFold, "E_xx nearly singular: stiffness from the reduction.")
      .value("snapped", EquilibriumStatus::kSnapped, "The state just left its branch (a snap-through).")
      .value("snapping", EquilibriumStatus::kSnapping, "A snap under way, spread over updates by a time budget.")
      .value("failed", EquilibriumStatus::kFailed, "No usable state: never render its force.");
  TextAsStr(status);
  py::enum_<Termination> termination(m, "Termination", "Why a solve stopped (str() gives the sweep CSV's text).");
  termination
      .value("converged", Termination::kConverged)
      .value("budget_spent", Termination::kBudgetSpent)
      .value("linear_solver_failed", Termination::kLinearSolverFailed)
      .value("non_finite", Termination::kNonFinite)
      .value("invalid_input", Termination::kInvalidInput)
      .value("snapping", Termination::kSnapping)
      .value("accuracy_limited", Termination::kAccuracyLimited,
             "At round-off with the certified force error above the tolerance (docs/accuracy.md).");
  TextAsStr(termination);
}

void BindStepResult(py::module_& m) {
  const auto summary = [](auto member) {
    return [member](const TrackResult& r) { return r.summary.*member; };
  };
  py::class_<TrackResult>(m, "StepResult",
                          "One update of a Tracker: the force on the grasp and its stiffness at the "
                          "equilibrium, with how the solve went. Arrays are read-only views into this object.")
      .def_property_readonly(
          "force", [](const TrackResult& r) -> const Vec& { return r.force; }, py::return_value_policy::reference_internal,
          "F = -E_u at the equilibrium, model force units (one entry per control).")
      .def_property_readonly(
          "stiffness", [](const TrackResult& r) -> const Mat& { return r.stiffness; },
          py::return_value_policy::reference_internal,
          "K = dF/du by implicit differentiation (controls x controls); finite near a fold.")
      .def_readonly("stiffness_regularized", &TrackResult::stiffness_regularized,
                    "K's near-zero eigenvalue was floored (near a fold).")
      .def_readonly("energy", &TrackResult::energy)
      .def_readonly("probe", &TrackResult::probe, "The model's one-number state summary (the CSV's probe).")
      .def_readonly("snapped", &TrackResult::snapped, "The state left its branch at this update.")
      .def_property_readonly("status", summary(&SolverSummary::status))
      .def_property_readonly("termination", summary(&SolverSummary::termination))
      .def_property_readonly("iterations", summary(&SolverSummary::iterations))
      .def_property_readonly("force_error", summary(&SolverSummary::force_error),
                             "Certified force error, model force units, max norm over the controls "
                             "(docs/accuracy.md); -1 where none could be estimated.")
      .def_property_readonly("force_target", summary(&SolverSummary::force_target),
                             "The force tolerance the solve stopped on (0: the cutoff alone).")
      .def_property_readonly("residual", summary(&SolverSummary::residual), "|E_x|_2 at the returned state.")
      .def_property_readonly("lambda_min", summary(&SolverSummary::lambda_min),
                             "Smallest eigenvalue estimate of E_xx at the returned state.")
      .def_property_readonly("negative_pivots", summary(&SolverSummary::negative_pivots),
                             "Inertia of E_xx (> 0: an unstable equilibrium; -1: not factorised).")
      .def_property_readonly("gradient_evaluations", summary(&SolverSummary::gradient_evaluations))
      .def_property_readonly("hessian_evaluations", summary(&SolverSummary::hessian_evaluations))
      .def_property_readonly("solve_us", summary(&SolverSummary::solve_us), "Wall time of the solve, microseconds.")
      .def_property_readonly("converged", [](const TrackResult& r) { return r.summary.IsConverged(); },
                             "An equilibrium to the requested accuracy or to round-off.")
      .def_property_readonly("usable", [](const TrackResult& r) { return r.summary.IsSolutionUsable(); },
                             "False: no usable state; its force must not be rendered.")
      .def_property_readonly("report", [](const TrackResult& r) { return r.summary.BriefReport(); })
      .def("__repr__", [](const TrackResult& r) {
        return "StepResult(status=" + std::string(ToString(r.summary.status)) +
               ", termination=" + ToString(r.summary.termination) +
               ", iterations=" + std::to_string(r.summary.iterations) + ")";
      });
}

void BindKnot(py::module_& m) {
  py::class_<topology::KnotInfo>(m, "KnotInfo", "The knot type of a curve (closed far away first).")
      .def_readonly("ok", &topology::KnotInfo::ok, "False: no generic projection found (see error).")
      .def_readonly("name", &topology::KnotInfo::name, "'unknot', 'trefoil', 'figure-eight', ...")
      .def_readonly("determinant", &topology::KnotInfo::determinant, "|Alexander(-1)|")
      .def_readonly("alexander", &topology::KnotInfo::alexander, "Alexander polynomial coefficients from t^0.")
      .def_readonly("crossings", &topology::KnotInfo::crossings)
      .def_readonly("error", &topology::KnotInfo::error)
      .def("__repr__", [](const topology::KnotInfo& k) { return "KnotInfo('" + k.name + "')"; });
  m.def(
      "identify_knot",
      [](const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& nodes) {
        py::gil_scoped_release release;
        return topology::IdentifyKnotXyz(std::span<const double>(nodes.data(), static_cast<size_t>(nodes.size())));
      },
      py::arg("nodes"), "The knot type of an open polyline given as a (k, 3) array of points.");
}

}  // namespace

void BindTracker(py::module_& m) {
  BindStatuses(m);
  BindStepResult(m);
  BindKnot(m);
  py::class_<PyTracker>(m, "Tracker",
                        "Follows a scene's quasi-static equilibrium as the grasp moves (the tracker the "
                        "server and snapthread-sweep use). Made at the scene's grasp.start, solved.")
      .def(py::init<const Scene&>(), py::arg("scene"))
      .def("step", &PyTracker::Step, py::arg("u"),
           "One control update to controls u (one entry per control): predictor, solve, force and "
           "stiffness. Releases the GIL.")
      .def("reset", &PyTracker::Reset, py::arg("u"),
           "Start again from the model's initial state at controls u, solved to the cutoff.")
      .def("resume", &PyTracker::Resume, py::arg("x"), py::arg("u"),
           "Start again from a saved equilibrium x at controls u.")
      .def_property_readonly(
          "state", [](const PyTracker& t) -> const Vec& { return t.tracker().state(); },
          py::return_value_policy::reference_internal,
          "The equilibrium x: a read-only view that the next update changes (copy it to keep it).")
      .def_property_readonly(
          "control", [](const PyTracker& t) -> const Vec& { return t.tracker().control(); },
          py::return_value_policy::reference_internal, "The current controls u (read-only view).")
      .def_property_readonly("last", [](const PyTracker& t) { return t.tracker().last(); },
                             "The last update's StepResult (a copy).")
      .def("nodes", &PyTracker::Nodes,
           "Node positions of the current shape, a (k, 3) array (z = 0 for planar models; zeeman: "
           "wheel centre, wheel point and both string anchors).")
      .def("knot", &PyTracker::Knot, "The current shape's KnotInfo for curves; None for zeeman and cusp.")
      .def_property(
          "options", [](const PyTracker& t) { return t.tracker().options(); }, &PyTracker::SetOptions,
          "The SolverOptions in use (a copy); assigning one switches without losing the state.")
      .def_property_readonly("scene", &PyTracker::scene, py::return_value_policy::reference_internal)
      .def_property_readonly("model", [](const PyTracker& t) { return std::string(t.tracker().model().Name()); })
      .def_property_readonly("num_states", [](const PyTracker& t) { return t.tracker().model().NumStates(); })
      .def_property_readonly("num_controls", [](const PyTracker& t) { return t.tracker().model().NumControls(); })
      .def_property_readonly("force_scale", [](const PyTracker& t) { return t.tracker().model().ForceScale(); },
                             "The model's characteristic force (force_tolerance is relative to it).");
}

}  // namespace snapthread::python
