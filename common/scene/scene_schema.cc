#include "scene/scene_schema.h"

#include <sstream>

#include "scene/scene.h"
#include "solvers/options.h"

namespace snapthread {
namespace {

std::string Triple(const std::array<double, 3>& v) {
  return "[" + SceneNumber(v[0]) + ", " + SceneNumber(v[1]) + ", " + SceneNumber(v[2]) + "]";
}

std::vector<SceneKey> TopAndGraspKeys() {
  const std::string top(kSceneTop), grasp(kSceneGrasp), named(kSceneNamedGrasp), point(kScenePathPoint);
  return {
      {top, "name", "the scene's name (messages and logs carry it)", "", "the model's name", "a string"},
      {top, "description", "one line for people", "", "\"\"", "a string"},
      {top, "model", "the registered model (its parameters: below)", "", "required", "a model name"},
      {top, "params", "the model's parameters (below, per model)", "", "each parameter's default",
       "a mapping"},
      {top, "grasp", "the one grasp of a single-grasp model", "", "required unless grasps:", "a mapping"},
      {top, "grasps", "the named grasps of a model with several (the rod's two ends)", "",
       "required for such a model", "a list, one per grasp site, in the model's order"},
      {top, "solver", "how each equilibrium is solved", "", "the defaults below", "a mapping"},
      {top, "device", "the map between the model and the haptic device", "", "the defaults below", "a mapping"},
      {top, "targets", "what `snapthread-bench --advise` sizes the model for", "", "none", "a mapping"},
      {grasp, "start", "the grasp's controls at the start", "model units", "required",
       "2 or 3 numbers (the model's dimension; a rod's rotation starts at 0)"},
      {grasp, "direction", "the grip direction d", "", "required with params.grip_direction: true",
       "3 numbers, not all 0; only with params.grip_direction: true"},
      {grasp, "path", "waypoints the scripted hand follows (demo, sweeps --path, tests)", "model units",
       "none", "a list of points like start (a rod's: [X, Y, Z] or a path point mapping)"},
      {named, "name", "the grasp's name (`snapthread-device --grasp NAME`)", "", "required",
       "a name without spaces or commas, unique"},
      {named, "edge", "the edge the grasp holds (negative: from the end)", "", "edge or node required",
       "the model's grasp sites in order"},
      {named, "node", "the node the grasp holds (negative: from the end)", "", "edge or node required",
       "the model's grasp sites in order"},
      {named, "model_origin", "the model point this grasp's device origin maps to", "model units",
       "device.model_origin", "3 numbers"},
      {point, "position", "the waypoint's position", "model units", "required", "3 numbers"},
      {point, "roll_deg", "rotation about the rod's axis at the grasp", "degrees", "0",
       "a number; not with rotation_deg"},
      {point, "rotation_deg", "rotation vector of the grasp", "degrees", "[0, 0, 0]",
       "3 numbers; not with roll_deg"},
  };
}

std::vector<SceneKey> SolverKeys() {
  const SolverOptions d{};
  const std::string s(kSceneSolver);
  return {
      {s, "method", "the solver", "", d.method, "newton, newton-ls or higher-order (the solver registry)"},
      {s, "cutoff", "stop when ‖E_x‖ < cutoff", "model force", SceneNumber(d.cutoff), "a number > 0"},
      {s, "force_tolerance", "also stop only when the certified force error is within this fraction of "
                             "the model's force scale (docs/accuracy.md)",
       "fraction of force scale", SceneNumber(d.force_tolerance), "a number >= 0 (0 = the cutoff alone)"},
      {s, "force_floor_n", "absolute floor of that tolerance at the device", "N", SceneNumber(d.force_floor_n),
       "a number >= 0 (0 = none)"},
      {s, "max_iterations", "iteration budget per update", "", std::to_string(d.max_iterations),
       "an integer >= 0 (0 = unlimited)"},
      {s, "time_budget_us", "wall-clock budget per update (a snap may spread over updates: "
                            "docs/time-budget.md)",
       "µs", SceneNumber(d.max_time_us), "a number >= 0 (0 = none)"},
      {s, "max_time_us", "earlier spelling of time_budget_us", "µs", SceneNumber(d.max_time_us),
       "as time_budget_us; not with it"},
      {s, "linear_solver", "LDLᵀ backend", "", d.linear_solver, "auto, cholmod, dense or banded"},
      {s, "degeneracy_ratio", "higher-order: a fold is near when λ₀ < ratio · λ₀,ref", "",
       SceneNumber(d.degeneracy_ratio), "a number in (0, 1)"},
      {s, "max_reduction_step", "higher-order: cap on the reduction's step |s|", "model units",
       SceneNumber(d.max_reduction_step), "a number > 0"},
      {s, "secant_predictor", "warm start by the secant near a fold (the tangent elsewhere)", "",
       d.secant_predictor ? "true" : "false", "true or false"},
      {s, "max_update_hz", "the server's cap on updates per second (--max-update-hz overrides)", "Hz", "0",
       "a number in [0, 100000] (0 = no cap)"},
      {s, "start_continuation", "number parameters the start solve continues from 0 when the direct "
                                "start finds no stable equilibrium",
       "", "[]", "a list of the model's number parameters whose range holds 0"},
  };
}

std::vector<SceneKey> DeviceAndTargetKeys() {
  const DeviceMapping d{};
  const std::string v(kSceneDevice), t(kSceneTargets);
  return {
      {v, "model_units_per_metre", "model units per metre of hand motion", "1/m", SceneNumber(d.model_units_per_metre),
       "a number > 0"},
      {v, "newtons_per_model_force", "newtons at the device per unit of model force", "N",
       SceneNumber(d.newtons_per_model_force), "a number > 0"},
      {v, "max_force_n", "force clamp at the device", "N", SceneNumber(d.max_force_n), "a number > 0"},
      {v, "max_stiffness_n_per_m", "stiffness clamp at the device", "N/m", SceneNumber(d.max_stiffness_n_per_m),
       "a number > 0"},
      {v, "workspace_radius_m", "the device workspace's radius", "m", SceneNumber(d.workspace_radius_m), "a number > 0"},
      {v, "model_origin", "the model point the device origin maps to", "model units", Triple(d.model_origin),
       "3 numbers"},
      {t, "force_error", "largest acceptable force error", "fraction of force scale",
       SceneNumber(kDefaultTargetForceError), "a number > 0"},
      {t, "rate_hz", "smallest acceptable update rate", "Hz", SceneNumber(kDefaultTargetRateHz), "a number > 0"},
  };
}

}  // namespace

std::string SceneNumber(double v) {
  std::ostringstream ss;
  ss << v;
  return ss.str();
}

const std::vector<SceneKey>& SceneKeys() {
  static const std::vector<SceneKey> keys = [] {
    std::vector<SceneKey> all = TopAndGraspKeys();
    for (auto& k : SolverKeys()) all.push_back(std::move(k));
    for (auto& k : DeviceAndTargetKeys()) all.push_back(std::move(k));
    return all;
  }();
  return keys;
}

std::set<std::string> SceneKeyNames(std::string_view block) {
  std::set<std::string> names;
  for (const SceneKey& k : SceneKeys())
    if (k.block == block) names.insert(k.name);
  return names;
}

}  // namespace snapthread
