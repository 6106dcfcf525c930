#include "tracking/make_tracker.h"

#include <stdexcept>
#include <string>

#include "models/registry.h"

namespace snapthread {

std::unique_ptr<EquilibriumTracker> MakeTracker(const Scene& scene) {
  std::unique_ptr<EquilibriumTracker> tracker;
  try {
    // The model's and the solver's messages start with the key ("params.n: ...").
    // The force floor is given in newtons at the device: the solver needs the map.
    SolverOptions options = scene.solver;
    options.newtons_per_model_force = scene.device.newtons_per_model_force;
    tracker = std::make_unique<EquilibriumTracker>(MakeModel(scene.params), options);
  } catch (const std::invalid_argument& e) {
    throw SceneError(scene.file + ": " + e.what());
  }
  if (scene.grasp_start.size() != tracker->model().NumControls()) {
    throw SceneError(scene.file + ": grasp.start has " + std::to_string(scene.grasp_start.size()) +
                     " entries, model " + std::string(tracker->model().Name()) + " has " +
                     std::to_string(tracker->model().NumControls()) + " controls");
  }
  tracker->SetSnapThreshold(0.1 * SnapLengthScale(scene.params));
  if (!scene.start_continuation.empty()) {
    // The family of the start continuation: the scene's model with those parameters
    // scaled by t (t = 1 is the scene's own model).
    tracker->SetStartContinuation([params = scene.params, names = scene.start_continuation](double t) {
      ModelParams p = params;
      for (const std::string& name : names) p.Set(name, t * params.Number(name));
      return MakeModel(p);
    });
  }
  return tracker;
}

}  // namespace snapthread
