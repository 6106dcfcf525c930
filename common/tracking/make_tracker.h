// The one scene -> tracker path: the server, the sweep, the stability suite, the bench
// and the advisor all build their EquilibriumTracker here, so one scene snaps at the
// same places everywhere (same model, solver and snap threshold).
#pragma once

#include <memory>

#include "scene/scene.h"
#include "tracking/tracker.h"

namespace snapthread {

// The model from the registry (scene.params), the solver from scene.solver, and the
// snap threshold 0.1 x the model's length scale (SnapLengthScale: the segment length of
// a chain, 1 otherwise). Bad parameters or solver options (an unknown linear solver,
// say) throw SceneError naming the scene file and the key, e.g.
// "scenes/x.yaml: solver.linear_solver: expected one of ..., got 'magic'".
std::unique_ptr<EquilibriumTracker> MakeTracker(const Scene& scene);

}  // namespace snapthread
