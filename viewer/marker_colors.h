// Colours of the markers drawn over the thread (grasps, contacts), shared by the renderer
// and the screenshot tests that look for them.
#pragma once

#include "mesh_builder.h"

namespace snapthread::viewer {

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
