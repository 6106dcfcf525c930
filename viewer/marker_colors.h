// Colours of the thread (its solver state) and of the markers drawn over it (grasps,
// contacts), shared by the renderer and the screenshot tests that look for them.
#pragma once

#include "mesh_builder.h"

namespace snapthread::viewer {

// Colour coding of the solver state (force_model_t.STATUS_*).
inline Rgb StatusColor(int status) {
  switch (status) {
    case 0: return {0.55f, 0.80f, 0.95f};  // regular: pale blue
    case 1: return {1.00f, 0.62f, 0.10f};  // near fold: orange
    case 2: return {0.95f, 0.20f, 0.20f};  // snapped: red
    case 4: return {0.85f, 0.35f, 0.75f};  // snapping (time budget): magenta
    default: return {0.55f, 0.55f, 0.55f};  // invalid: grey
  }
}
inline const Rgb kBackground(0.11f, 0.12f, 0.15f);

// One colour per grasp, in the order of thread_shape_t.grasps (repeating past the last):
// yellow is the first (the single grasp's colour), then green, cyan, orange.
inline Rgb GraspColor(int index) {
  static const Rgb kColors[] = {{1.0f, 0.85f, 0.2f}, {0.3f, 0.95f, 0.3f},
                                {0.2f, 0.9f, 0.95f}, {1.0f, 0.55f, 0.1f}};
  return kColors[index % 4];
}
// Active self-contact: the two closest points and the segment between them, white (no
// solver state colour is white, so a contact stands out on any tube).
inline const Rgb kContactColor(1.0f, 1.0f, 1.0f);
// The force arrow on a grasp.
inline const Rgb kForceArrowColor(1.0f, 0.35f, 0.25f);

}  // namespace snapthread::viewer
