// Scenes: YAML files in scenes/ describing a model, its grasp, solver and device mapping.
// A bad scene is refused at load with the file, the key and what was expected.
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "models/models.h"
#include "solvers/options.h"

namespace snapthread {

// Maps device metres to model units and model forces to newtons, with the device
// limits the scene asks for (the device client also clamps to its own capabilities).
struct DeviceMapping {
  double model_units_per_metre = 100.0;  // 1 cm of hand motion = 1 model unit
  double newtons_per_model_force = 1.0;
  double max_force_n = 3.0;
  double max_stiffness_n_per_m = 800.0;
  double workspace_radius_m = 0.08;
  // Model-space point that the device origin maps to.
  std::array<double, 3> model_origin = {0.0, 0.0, 0.0};
};

// One grasp of a scene: a scene with `grasps:` names several, each holding a
// part of the model (the model's grasp sites, models/registry.h) and taking
// grasp_layout.NumControls() controls of u, in the order listed. A scene with the single
// `grasp:` has one, named "" (the only grasp, as devices and messages call it).
struct SceneGrasp {
  std::string name;
  std::string holds;  // "edge 0", "edge 59"; "" for the single grasp
  int offset = 0;     // its first control in u
  // The model point this grasp's device origin maps to (`model_origin:` of the grasp):
  // each hand works about its own end. Unset: the scene's device.model_origin.
  bool has_model_origin = false;
  std::array<double, 3> model_origin = {0.0, 0.0, 0.0};
};

struct Scene {
  std::string file;         // where it was loaded from ("<string>" for text)
  std::string name;
  std::string description;
  ModelParams params;
  GraspLayout grasp_layout;  // the controls of one grasp as a device sees them
  std::vector<SceneGrasp> grasps;  // at least one
  Vec grasp_start;          // initial controls u (size = model controls: every grasp's, in order)
  // Scripted path of the grasp through the scene's snaps (waypoints in control space,
  // every grasp's controls at each point), used by the demo, the device client's scripted
  // backends and the tests.
  std::vector<Vec> path;
  SolverOptions solver;
  // solver.max_update_hz: the server's cap on equilibrium updates per second
  // (0 = none). The server's --max-update-hz overrides it.
  double max_update_hz = 0.0;
  // solver.start_continuation: number parameters of the model (e.g. the rod's
  // natural_curvature) that the start solve continues from 0 to their value here when
  // the direct start from the model's initial state reaches no stable equilibrium (a
  // rod with coil memory held straight is a saddle): MakeTracker hands the tracker that
  // family of models (EquilibriumTracker::SetStartContinuation). Empty: no continuation.
  std::vector<std::string> start_continuation;
  DeviceMapping device;
  // Optional targets for "model no more than a scene needs".
  double target_force_error = 0.0;  // relative to the model's force scale; 0 = none
  double target_rate_hz = 0.0;
};

// The index in scene.grasps of the grasp called `name`, -1 when there is none ("" names
// the first grasp of any scene, so a client without --grasp binds as before).
int FindGrasp(const Scene& scene, const std::string& name);
// The device mapping of grasp `grasp` (an index into scene.grasps; the scene's mapping
// for a scene without grasps): the scene's, about the grasp's own model origin.
DeviceMapping GraspDeviceMapping(const Scene& scene, int grasp);

class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// key=value overrides, value parsed as YAML ("params.n=20", "solver.method=newton").
struct SceneOverride {
  std::string key;
  std::string value;
};

// Largest scene file LoadScene reads (the shipped scenes are under 2 kB): a wrong file
// (a log, an image, /dev/zero) is refused by its size before any parsing.
inline constexpr std::size_t kMaxSceneFileBytes = std::size_t{1} << 20;  // 1 MiB

// Reads `path` (a regular file of at most kMaxSceneFileBytes, opened without blocking:
// a FIFO or a device is refused, scene/input_file.h) and parses it.
Scene LoadScene(const std::string& path, const std::vector<SceneOverride>& overrides = {});
Scene ParseScene(const std::string& yaml_text, const std::string& file_label,
                 const std::vector<SceneOverride>& overrides = {});
// Parses "a.b=value"; throws SceneError for a malformed one.
SceneOverride ParseOverride(const std::string& text);

}  // namespace snapthread
