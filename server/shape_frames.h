// thread_shape_t.frames for a viewer: the material director m1 and
// twist density per edge of a model with frames (FramesCapability, the rod); every other
// model sends none.
#pragma once

#include "models/model.h"
#include "numeric/types.h"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::server {

// Sets msg->frames / num_frames: for a model with frames (Model::frames(), the rod) one
// row per edge, (m1 x, y, z, twist density in rad per model length), in the order of the
// edges (row j joins nodes j and j + 1); otherwise, or when x / u do not fit the model or
// a value is not finite, none.
void FillShapeFrames(const Model& model, const Vec& x, const Vec& u, thread_shape_t* msg);

}  // namespace snapthread::server
